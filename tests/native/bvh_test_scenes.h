// Scenes and rays for the BVH tests: small, deterministic, and chosen to break traversal
// (shared edges and vertices, slivers, coplanar and duplicated triangles, extreme scales).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "bvh/aabb.h"
#include "bvh/intersect.h"
#include "procedural/bumpy_sphere_mesh.h"

namespace glslppm::bvh_test {

// n triangles with independent vertices, random sizes (a few spanning half the scene) in
// [-1, 1]^3.
OwnedMesh make_random_soup(std::size_t n, std::uint32_t seed);
// The Cornell box (0..555, as in the original measurements): walls, light, two blocks; quads
// split in two triangles sharing an edge, vertices shared between triangles.
OwnedMesh make_cornell_box();
// n slivers: length 0.2 to 1 in a [-1, 1]^3 scene, width 1e-4 of that, random orientation.
OwnedMesh make_thin_triangles(std::size_t n, std::uint32_t seed);
// A grid in the plane z = 0 with shared edges, overlapping coplanar triangles, exact
// duplicates of triangles (equal t: the smaller id must win) and a tilted duplicated fan.
OwnedMesh make_coplanar_duplicates(std::uint32_t seed);

// Random rays of every kind the tests need, cycling through all six direction classes:
// origins inside and outside the scene bounds, random directions, axis-parallel directions
// (one or two zero components, origins on vertex coordinates), rays aimed at vertices,
// at points on edges (shared edges included) and at triangle interiors; some with tmin > 0
// or a finite tmax.
std::vector<Ray> make_test_rays(const OwnedMesh& mesh, std::size_t count, std::uint32_t seed);

// Definitions (header-only: CMake compiles only *_test.cpp from tests/native).

namespace detail {

using Rng = std::mt19937;

inline float uniform(Rng& rng, float lo = 0.0f, float hi = 1.0f) {
    return std::uniform_real_distribution<float>(lo, hi)(rng);
}

inline glm::vec3 random_unit(Rng& rng) {
    for (;;) {
        const glm::vec3 p(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
        const float l2 = glm::dot(p, p);
        if (l2 > 1e-4f && l2 <= 1.0f) return p / std::sqrt(l2);
    }
}

inline void add_triangle(OwnedMesh& m, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    m.positions.insert(m.positions.end(), {a, b, c});
    m.triangles.emplace_back(base, base + 1, base + 2);
}

// A quad a-b-c-d as two triangles sharing the diagonal a-c and the vertices.
inline void add_quad(OwnedMesh& m, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                     const glm::vec3& d) {
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    m.positions.insert(m.positions.end(), {a, b, c, d});
    m.triangles.emplace_back(base, base + 1, base + 2);
    m.triangles.emplace_back(base, base + 2, base + 3);
}

// An axis-aligned block given by its 8 corners, 12 triangles sharing vertices.
inline void add_block(OwnedMesh& m, const glm::vec3& lo, const glm::vec3& hi) {
    const auto base = static_cast<std::uint32_t>(m.positions.size());
    for (int i = 0; i < 8; ++i)
        m.positions.emplace_back(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    const int faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                             {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
    for (const auto& f : faces) {
        m.triangles.emplace_back(base + f[0], base + f[1], base + f[2]);
        m.triangles.emplace_back(base + f[0], base + f[2], base + f[3]);
    }
}

}  // namespace detail
using namespace detail;

inline OwnedMesh make_random_soup(std::size_t n, std::uint32_t seed) {
    Rng rng(seed);
    OwnedMesh m;
    // Typical size: a few times the mean spacing, so that rays see overlapping triangles.
    const float size = 3.0f / std::cbrt(static_cast<float>(std::max<std::size_t>(n, 1)));
    for (std::size_t i = 0; i < n; ++i) {
        const glm::vec3 c(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
        // A few (at most 21) span half the scene.
        const float s = (i % 97 == 0 && i < 2000) ? 1.0f : size * uniform(rng, 0.2f, 1.0f);
        add_triangle(m, c + s * random_unit(rng), c + s * random_unit(rng),
                     c + s * random_unit(rng));
    }
    return m;
}

inline OwnedMesh make_cornell_box() {
    OwnedMesh m;
    const float w = 555.0f;
    add_quad(m, {0, 0, 0}, {w, 0, 0}, {w, 0, w}, {0, 0, w});                          // floor
    add_quad(m, {0, w, 0}, {0, w, w}, {w, w, w}, {w, w, 0});                          // ceiling
    add_quad(m, {0, 0, w}, {w, 0, w}, {w, w, w}, {0, w, w});                          // back
    add_quad(m, {0, 0, 0}, {0, 0, w}, {0, w, w}, {0, w, 0});                          // left
    add_quad(m, {w, 0, 0}, {w, w, 0}, {w, w, w}, {w, 0, w});                          // right
    add_quad(m, {213, 554, 227}, {343, 554, 227}, {343, 554, 332}, {213, 554, 332});  // light
    add_block(m, {130, 0, 65}, {295, 165, 230});                                      // short block
    add_block(m, {265, 0, 295}, {430, 330, 460});                                     // tall block
    return m;
}

inline OwnedMesh make_thin_triangles(std::size_t n, std::uint32_t seed) {
    Rng rng(seed);
    OwnedMesh m;
    for (std::size_t i = 0; i < n; ++i) {
        const glm::vec3 c(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
        const glm::vec3 axis = random_unit(rng) * uniform(rng, 0.1f, 0.5f);
        glm::vec3 side = glm::cross(axis, random_unit(rng));
        side *= 1e-4f * glm::length(axis) / std::max(glm::length(side), 1e-20f);
        // Some are axis-aligned slivers (boxes flat in one or two dimensions).
        if (i % 5 == 0) {
            const int k = static_cast<int>(i / 5 % 3);
            glm::vec3 a(0.0f), s(0.0f);
            a[k] = glm::length(axis);
            s[(k + 1) % 3] = 1e-4f * a[k];
            add_triangle(m, c - a, c + a, c + s);
        } else {
            add_triangle(m, c - axis, c + axis, c + side);
        }
    }
    return m;
}

inline OwnedMesh make_coplanar_duplicates(std::uint32_t seed) {
    Rng rng(seed);
    OwnedMesh m;
    // A 16 x 16 grid of quads in z = 0, vertices shared.
    const int g = 16;
    for (int y = 0; y <= g; ++y)
        for (int x = 0; x <= g; ++x)
            m.positions.emplace_back(-1.0f + 2.0f * x / g, -1.0f + 2.0f * y / g, 0.0f);
    for (int y = 0; y < g; ++y)
        for (int x = 0; x < g; ++x) {
            const auto a = static_cast<std::uint32_t>(y * (g + 1) + x);
            const std::uint32_t b = a + 1, c = a + g + 2, d = a + g + 1;
            m.triangles.emplace_back(a, b, c);
            m.triangles.emplace_back(a, c, d);
        }
    // Overlapping coplanar triangles in z = 0 and in z = 0.5.
    for (int i = 0; i < 200; ++i) {
        const float z = i % 2 ? 0.0f : 0.5f;
        const glm::vec3 c(uniform(rng, -1, 1), uniform(rng, -1, 1), z);
        auto jitter = [&] {
            return glm::vec3(uniform(rng, -0.3f, 0.3f), uniform(rng, -0.3f, 0.3f), 0.0f);
        };
        add_triangle(m, c + jitter(), c + jitter(), c + jitter());
    }
    // Exact duplicates: the same vertex indices and copies of the vertices.
    const std::size_t existing = m.triangles.size();
    for (std::size_t i = 0; i < existing; i += 3) m.triangles.push_back(m.triangles[i]);
    for (std::size_t i = 1; i < existing; i += 7) {
        const glm::uvec3 t = m.triangles[i];
        add_triangle(m, m.positions[t.x], m.positions[t.y], m.positions[t.z]);
    }
    // A tilted fan around a shared centre vertex, stored twice.
    for (int copy = 0; copy < 2; ++copy) {
        const auto centre = static_cast<std::uint32_t>(m.positions.size());
        m.positions.emplace_back(0.1f, 0.2f, 0.3f);
        const int k = 24;
        for (int i = 0; i < k; ++i) {
            const float a = 2.0f * 3.14159265f * i / k;
            m.positions.emplace_back(0.1f + 0.7f * std::cos(a), 0.2f + 0.7f * std::sin(a),
                                     0.3f + 0.35f * std::cos(a) + 0.2f * std::sin(a));
        }
        for (int i = 0; i < k; ++i)
            m.triangles.emplace_back(centre, centre + 1 + i, centre + 1 + (i + 1) % k);
    }
    return m;
}

inline std::vector<Ray> make_test_rays(const OwnedMesh& mesh, std::size_t count,
                                       std::uint32_t seed) {
    Rng rng(seed);
    Aabb bounds;
    for (const glm::vec3& p : mesh.positions) bounds.grow(p);
    const glm::vec3 centre = bounds.centroid();
    const glm::vec3 half = glm::max(bounds.extent() * 0.5f, glm::vec3(bounds.magnitude() * 1e-3f));
    const float size = glm::length(half);  // unit of ray lengths, so tmin/tmax scale too
    auto point_in = [&](float factor) {
        return centre +
               half * factor *
                   glm::vec3(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    };
    auto vertex = [&](std::uint32_t tri, int k) { return mesh.positions[mesh.triangles[tri][k]]; };
    std::uniform_int_distribution<std::uint32_t> pick_tri(
        0, static_cast<std::uint32_t>(mesh.triangles.size() - 1));
    // A random direction of class cls: the dominant component on axis cls/2 with the class
    // sign, strictly larger than those of lower axes (ties go to the lower axis).
    auto class_dir = [&](int cls) {
        glm::vec3 d = random_unit(rng);
        const int axis = cls / 2;
        const glm::vec3 a = glm::abs(d);
        int big = 0;
        if (a.y > a.x) big = 1;
        if (a.z > a[big]) big = 2;
        std::swap(d[big], d[axis]);
        d[axis] = (cls & 1) ? -std::abs(d[axis]) : std::abs(d[axis]);
        for (int k = 0; k < axis; ++k)
            if (std::abs(d[k]) >= std::abs(d[axis])) d[k] *= 0.5f;
        return d;
    };

    std::vector<Ray> rays;
    rays.reserve(count);
    for (std::size_t i = 0; i < count; ++i) {
        Ray ray;
        const int cls = static_cast<int>(i % 6);
        const int kind = static_cast<int>(i / 6 % 8);
        glm::vec3 target;
        bool aimed = true;
        switch (kind) {
            case 2:
                target = vertex(pick_tri(rng), static_cast<int>(rng() % 3));
                break;
            case 3: {  // a point on an edge: the midpoint (exact for shared edges) or any
                const std::uint32_t t = pick_tri(rng);
                const int k = static_cast<int>(rng() % 3);
                const float f = rng() % 2 ? 0.5f : uniform(rng);
                target = vertex(t, k) + f * (vertex(t, (k + 1) % 3) - vertex(t, k));
                break;
            }
            case 4:
            case 5: {  // a triangle interior
                const std::uint32_t t = pick_tri(rng);
                float a = uniform(rng), b = uniform(rng);
                if (a + b > 1.0f) a = 1.0f - a, b = 1.0f - b;
                target = vertex(t, 0) + a * (vertex(t, 1) - vertex(t, 0)) +
                         b * (vertex(t, 2) - vertex(t, 0));
                break;
            }
            default:
                aimed = false;
                break;  // 0, 1: random; 6, 7: axis-parallel
        }
        if (aimed) {
            // From close by (often inside the bounds) or from afar, through the target at t ~ 1.
            const float distance =
                size * (rng() % 2 ? uniform(rng, 0.01f, 0.5f) : uniform(rng, 0.5f, 4.0f));
            ray.origin = target - class_dir(cls) * distance;
            ray.dir = target - ray.origin;
            if (select_order(ray.dir) != cls) ray.dir = class_dir(cls) * distance;  // rounding
        } else {
            ray.origin = point_in(kind % 2 ? 1.0f : 3.0f);  // inside or around the bounds
            ray.dir = class_dir(cls) * size;
        }
        if (kind >= 6) {
            // Zero one or both of the non-dominant components; now and then put the origin
            // on a vertex coordinate, so that rays run inside planes of axis-aligned faces.
            const int axis = cls / 2;
            const int zeros = 1 + static_cast<int>(rng() % 2);
            const int first = (axis + 1 + static_cast<int>(rng() % 2)) % 3;
            int zeroed[2] = {first, 3 - axis - first};
            const bool on_vertex = rng() % 2;
            const glm::vec3 v = vertex(pick_tri(rng), static_cast<int>(rng() % 3));
            for (int z = 0; z < zeros; ++z) {
                ray.dir[zeroed[z]] = 0.0f;
                if (on_vertex) ray.origin[zeroed[z]] = v[zeroed[z]];
            }
        }
        ray.tmin = 0.0f;
        ray.tmax = std::numeric_limits<float>::infinity();
        if (i % 11 == 3) ray.tmin = uniform(rng, 0.0f, 0.8f);
        if (i % 13 == 5) ray.tmax = uniform(rng, 0.2f, 1.5f);
        rays.push_back(ray);
    }
    return rays;
}

}  // namespace glslppm::bvh_test
