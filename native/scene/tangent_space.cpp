#include "scene/tangent_space.h"

#include <algorithm>
#include <cmath>

namespace glslppm {
namespace {

constexpr float kOctScale = 16383.0f;  // 15-bit signed: [-16383, 16383]

float sign_not_zero(float v) { return v >= 0.0f ? 1.0f : -1.0f; }

// Any unit vector orthogonal to n (Duff et al. 2017).
glm::vec3 any_orthogonal(const glm::vec3& n) {
    const float s = std::copysign(1.0f, n.z);
    const float a = -1.0f / (s + n.z);
    return {1.0f + s * n.x * n.x * a, s * n.x * n.y * a, -s * n.x};
}

}  // namespace

std::uint32_t pack_tangent(const glm::vec4& tangent) {
    glm::vec3 t(tangent);
    const float l1 = std::abs(t.x) + std::abs(t.y) + std::abs(t.z);
    glm::vec2 o(0.0f);
    if (l1 > 0.0f) {
        t /= l1;
        o = glm::vec2(t.x, t.y);
        if (t.z < 0.0f)
            o = glm::vec2((1.0f - std::abs(t.y)) * sign_not_zero(t.x),
                          (1.0f - std::abs(t.x)) * sign_not_zero(t.y));
    }
    auto word = [](float v) {
        const auto q = static_cast<std::int32_t>(std::lround(std::clamp(v, -1.0f, 1.0f) * kOctScale));
        return static_cast<std::uint32_t>(q + 16383) & 0x7FFFu;
    };
    return word(o.x) | word(o.y) << 15 | (tangent.w < 0.0f ? 0x80000000u : 0u);
}

glm::vec4 unpack_tangent(std::uint32_t bits) {
    const glm::vec2 o(static_cast<float>(static_cast<std::int32_t>(bits & 0x7FFFu) - 16383) / kOctScale,
                      static_cast<float>(static_cast<std::int32_t>((bits >> 15) & 0x7FFFu) - 16383) /
                          kOctScale);
    glm::vec3 t(o.x, o.y, 1.0f - std::abs(o.x) - std::abs(o.y));
    if (t.z < 0.0f) {
        t.x = (1.0f - std::abs(o.y)) * sign_not_zero(o.x);
        t.y = (1.0f - std::abs(o.x)) * sign_not_zero(o.y);
    }
    return glm::vec4(glm::normalize(t), (bits & 0x80000000u) ? -1.0f : 1.0f);
}

std::vector<glm::vec4> generate_tangents(std::span<const glm::vec3> positions,
                                         std::span<const glm::uvec3> triangles,
                                         std::span<const glm::vec3> normals,
                                         std::span<const glm::vec2> uvs) {
    std::vector<glm::dvec3> tan(positions.size(), glm::dvec3(0.0)), bit(positions.size(), glm::dvec3(0.0));
    std::vector<glm::dvec3> face(positions.size(), glm::dvec3(0.0));
    for (const glm::uvec3& tri : triangles) {
        const glm::dvec3 p0(positions[tri.x]), e1 = glm::dvec3(positions[tri.y]) - p0,
                                               e2 = glm::dvec3(positions[tri.z]) - p0;
        const glm::dvec2 w0(uvs[tri.x]), d1 = glm::dvec2(uvs[tri.y]) - w0,
                                         d2 = glm::dvec2(uvs[tri.z]) - w0;
        // p - p0 = e1 a + e2 b with uv - uv0 = d1 a + d2 b gives dp/du and dp/dv; their
        // directions are summed weighted by the triangle's area.
        const double det = d1.x * d2.y - d2.x * d1.y;
        const glm::dvec3 n = glm::cross(e1, e2);  // twice the area, along the winding
        for (int k = 0; k < 3; ++k) face[tri[k]] += n;
        const glm::dvec3 dpdu = (e1 * d2.y - e2 * d1.y) / det;
        const glm::dvec3 dpdv = (e2 * d1.x - e1 * d2.x) / det;
        if (det == 0.0 || !(glm::length(dpdu) > 0.0) || !(glm::length(dpdv) > 0.0)) continue;
        const double area = glm::length(n);
        for (int k = 0; k < 3; ++k) {
            tan[tri[k]] += glm::normalize(dpdu) * area;
            bit[tri[k]] += glm::normalize(dpdv) * area;
        }
    }
    std::vector<glm::vec4> out(positions.size());
    for (std::size_t v = 0; v < positions.size(); ++v) {
        glm::dvec3 n = normals.empty() ? face[v] : glm::dvec3(normals[v]);
        const double nl = glm::length(n);
        n = nl > 0.0 ? n / nl : glm::dvec3(0.0, 0.0, 1.0);
        glm::dvec3 t = tan[v] - n * glm::dot(n, tan[v]);  // Gram-Schmidt
        const double tl = glm::length(t);
        if (!(tl > 1e-20 * (glm::length(tan[v]) + 1e-30))) {
            out[v] = glm::vec4(any_orthogonal(glm::vec3(n)), 1.0f);
            continue;
        }
        t /= tl;
        const float sign = glm::dot(glm::cross(n, t), bit[v]) < 0.0 ? -1.0f : 1.0f;
        out[v] = glm::vec4(glm::vec3(t), sign);
    }
    return out;
}

}  // namespace glslppm
