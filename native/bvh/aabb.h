// Axis-aligned bounding boxes: the bounding volume of every BVH node.
#pragma once

#include <cmath>
#include <glm/glm.hpp>
#include <limits>

namespace glslppm {

struct Aabb {
    // Empty box: lo = +inf, hi = -inf, so that growing it by any point gives that point.
    glm::vec3 lo{std::numeric_limits<float>::infinity()};
    glm::vec3 hi{-std::numeric_limits<float>::infinity()};

    static Aabb of_triangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
        return Aabb{glm::min(glm::min(a, b), c), glm::max(glm::max(a, b), c)};
    }

    bool empty() const { return !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z); }

    void grow(const glm::vec3& p) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    void grow(const Aabb& b) {
        lo = glm::min(lo, b.lo);
        hi = glm::max(hi, b.hi);
    }

    glm::vec3 extent() const { return hi - lo; }
    glm::vec3 centroid() const { return (lo + hi) * 0.5f; }

    // Half the surface area (the SAH only needs ratios); 0 for an empty box.
    float half_area() const {
        if (empty()) return 0.0f;
        const glm::vec3 e = extent();
        return e.x * e.y + e.y * e.z + e.z * e.x;
    }
    float surface_area() const { return 2.0f * half_area(); }

    bool contains(const Aabb& b) const {
        return lo.x <= b.lo.x && lo.y <= b.lo.y && lo.z <= b.lo.z && hi.x >= b.hi.x &&
               hi.y >= b.hi.y && hi.z >= b.hi.z;
    }
    bool contains(const glm::vec3& p) const {
        return lo.x <= p.x && lo.y <= p.y && lo.z <= p.z && hi.x >= p.x && hi.y >= p.y &&
               hi.z >= p.z;
    }

    // Largest absolute coordinate of the box: the magnitude that float rounding is relative to.
    float magnitude() const {
        const glm::vec3 m = glm::max(glm::abs(lo), glm::abs(hi));
        return std::fmax(m.x, std::fmax(m.y, m.z));
    }
};

// Relative padding of BVH leaf boxes and of the per-triangle hit confirmation (intersect.h):
// 2^-19 of the box's largest absolute coordinate, i.e. at least 16 float ulps of every
// coordinate, at any scene scale (no absolute epsilon: scenes span 1e-3 to 1e5 units).
constexpr float kBoxPadRelative = 1.0f / 524288.0f;

// Grows the box outwards by kBoxPadRelative of its magnitude. Monotone: a box containing
// another gives a padded box containing the other's padded box, also after rounding.
inline Aabb pad_box(const Aabb& box) {
    const float pad = box.magnitude() * kBoxPadRelative;
    return Aabb{box.lo - pad, box.hi + pad};
}

}  // namespace glslppm
