#include "loaders/triangulate_polygon.h"

#include <cmath>

namespace glslppm {
namespace {

// Newell's method: the area-weighted normal of a polygon, robust for non-planar input.
glm::vec3 newell_normal(std::span<const glm::vec3> p) {
    glm::vec3 n(0.0f);
    for (std::size_t i = 0; i < p.size(); ++i) {
        const glm::vec3& a = p[i];
        const glm::vec3& b = p[(i + 1) % p.size()];
        n += glm::vec3((a.y - b.y) * (a.z + b.z), (a.z - b.z) * (a.x + b.x),
                       (a.x - b.x) * (a.y + b.y));
    }
    return n;
}

float cross2(glm::vec2 o, glm::vec2 a, glm::vec2 b) {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

bool inside(glm::vec2 p, glm::vec2 a, glm::vec2 b, glm::vec2 c) {
    return cross2(a, b, p) >= 0.0f && cross2(b, c, p) >= 0.0f && cross2(c, a, p) >= 0.0f;
}

void fan(const std::vector<std::uint32_t>& ring, std::vector<glm::uvec3>& out) {
    for (std::size_t i = 1; i + 1 < ring.size(); ++i)
        out.emplace_back(ring[0], ring[i], ring[i + 1]);
}

}  // namespace

std::vector<glm::uvec3> triangulate_polygon(std::span<const glm::vec3> corners) {
    std::vector<glm::uvec3> out;
    std::vector<std::uint32_t> ring(corners.size());
    for (std::size_t i = 0; i < ring.size(); ++i) ring[i] = std::uint32_t(i);
    if (corners.size() < 3) return out;
    const glm::vec3 n = newell_normal(corners);
    const glm::vec3 m = glm::abs(n);
    if (!(m.x + m.y + m.z > 0.0f) || !std::isfinite(m.x + m.y + m.z)) {
        fan(ring, out);
        return out;
    }
    // Project along the normal's largest axis, mirrored so that the polygon turns
    // counter-clockwise in the plane.
    const int axis = m.x >= m.y && m.x >= m.z ? 0 : (m.y >= m.z ? 1 : 2);
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    const float flip = n[axis] < 0.0f ? -1.0f : 1.0f;
    std::vector<glm::vec2> q(corners.size());
    for (std::size_t i = 0; i < q.size(); ++i) q[i] = {corners[i][u], flip * corners[i][v]};
    while (ring.size() > 3) {
        bool clipped = false;
        for (std::size_t i = 0; i < ring.size() && !clipped; ++i) {
            const std::uint32_t a = ring[(i + ring.size() - 1) % ring.size()], b = ring[i],
                                c = ring[(i + 1) % ring.size()];
            if (cross2(q[a], q[b], q[c]) <= 0.0f) continue;  // reflex or flat: not an ear
            bool empty = true;
            for (std::uint32_t k : ring)
                if (k != a && k != b && k != c && inside(q[k], q[a], q[b], q[c])) empty = false;
            if (!empty) continue;
            out.emplace_back(a, b, c);
            ring.erase(ring.begin() + std::ptrdiff_t(i));
            clipped = true;
        }
        if (!clipped) break;
    }
    fan(ring, out);
    return out;
}

}  // namespace glslppm
