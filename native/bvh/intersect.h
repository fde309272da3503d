// Ray-triangle and ray-box tests shared by the BVH traversal and the brute-force
// reference. shaders/common/mtbvh.glsl mirrors these functions line by line; change both.
//
// Exactness contract: brute force, TBVH and MTBVH all accept a triangle hit by the same
// rule on the very same floats and keep the closest by is_closer() (smallest t, ties to the
// smaller ORIGINAL triangle id), which does not depend on the order triangles are visited.
// The rule (hit_triangle) is Moller-Trumbore, confirmed by the slab test of the triangle's
// own padded box over [tmin, t]. The confirmation is what makes agreement exact rather than
// likely: for grazing rays Moller-Trumbore's t can be off by far more than any box padding
// (its error grows as 1/det), putting the "hit" outside the triangle's box. hit_box is
// monotone in the box and in tmax, every BVH box contains the padded boxes of its triangles
// (aabb.h, pad_box), and traversal tests boxes against the best t so far (>= the t of any
// hit that can still win), so no box on the way to an accepted hit can fail its test.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <limits>

#include "bvh/aabb.h"

namespace glslppm {

struct Ray {
    glm::vec3 origin;
    glm::vec3 dir;  // need not be normalized; zero components are allowed
    float tmin = 0.0f;
    float tmax = std::numeric_limits<float>::infinity();
};

struct Hit {
    float t = std::numeric_limits<float>::infinity();
    float u = 0.0f, v = 0.0f;    // barycentrics of v1 and v2
    std::int32_t triangle = -1;  // ORIGINAL triangle id (index into MeshView::triangles)
};

// A hit in a two-level tree (two_level_bvh.h); a one-level walk leaves instance at -1.
struct InstanceHit {
    float t = std::numeric_limits<float>::infinity();
    float u = 0.0f, v = 0.0f;
    std::int32_t instance = -1;  // -1: a miss, or a one-level tree's hit
    std::int32_t triangle = -1;  // ORIGINAL triangle id in the instance's mesh; -1: a miss
};

// pbrt-v4's gamma(n) = n*eps/(1 - n*eps), eps = 2^-24: a bound on the relative error of n
// rounded float operations (Pharr et al., Physically Based Rendering, 4th ed., eq. 6.14).
constexpr float bvh_gamma(int n) {
    constexpr float eps = 0.5f * std::numeric_limits<float>::epsilon();
    return (n * eps) / (1.0f - n * eps);
}
// Relative slack on the far side of the slab test. pbrt (4th ed., section 6.8.2) uses
// tFar *= 1 + 2*gamma(3) to cover the slab arithmetic; we widen it to 2^-14 so that the
// confirmation of a hit also absorbs Moller-Trumbore's own error in t, down to grazing
// angles of about half a degree; nearly parallel hits beyond that are dropped rather than
// returned at a point outside their triangle. The extra boxes this visits are negligible.
constexpr float kSlabFarScale = 1.0f + 1.0f / 16384.0f;
static_assert(kSlabFarScale > 1.0f + 2.0f * bvh_gamma(3));

// The MTBVH link set for a ray: axis = largest |dir| component (ties to the lower axis),
// order = 2*axis + (dir[axis] < 0). Hachisuka 2015, Figure 3, first line.
inline int select_order(const glm::vec3& d) {
    const glm::vec3 a = glm::abs(d);
    int axis = 0;
    if (a.y > a.x) axis = 1;
    if (a.z > a[axis]) axis = 2;
    return 2 * axis + (d[axis] < 0.0f ? 1 : 0);
}

// 1/dir without infinities: a zero (or denormal) component becomes +-1e37, so that
// (box - origin) * inv_dir is never 0 * inf = NaN; the resulting slab distances (>= 1e27
// for any coordinate difference the scene can hold) stay effectively infinite.
inline glm::vec3 safe_inverse_dir(const glm::vec3& d) {
    glm::vec3 inv;
    for (int k = 0; k < 3; ++k) {
        const float c = glm::abs(d[k]) > 1e-37f ? d[k] : (d[k] < 0.0f ? -1e-37f : 1e-37f);
        inv[k] = 1.0f / c;
    }
    return inv;
}

// Slab test against the closed box [lo, hi] for the segment [tmin, tmax] (inclusive at both
// ends, so a box entered exactly at the best t so far is still visited). Rays starting
// inside the box give a negative entry distance, clamped by tmin.
inline bool hit_box(const glm::vec3& lo, const glm::vec3& hi, const glm::vec3& origin,
                    const glm::vec3& inv_dir, float tmin, float tmax) {
    const glm::vec3 t_lo = (lo - origin) * inv_dir;
    const glm::vec3 t_hi = (hi - origin) * inv_dir;
    const glm::vec3 t_near = glm::min(t_lo, t_hi);
    const glm::vec3 t_far = glm::max(t_lo, t_hi);
    const float t0 = glm::max(glm::max(t_near.x, t_near.y), glm::max(t_near.z, tmin));
    const float t1 = glm::min(glm::min(t_far.x, t_far.y), glm::min(t_far.z, tmax));
    return t0 <= t1 * kSlabFarScale;
}

// Moller-Trumbore (1997) with inclusive edges: u >= 0, v >= 0, u + v <= 1; det == 0 (ray in
// the triangle's plane) is a miss; t must lie in the open interval (tmin, tmax).
inline bool intersect_triangle(const glm::vec3& origin, const glm::vec3& dir, float tmin,
                               float tmax, const glm::vec3& v0, const glm::vec3& v1,
                               const glm::vec3& v2, float& t, float& u, float& v) {
    const glm::vec3 e1 = v1 - v0;
    const glm::vec3 e2 = v2 - v0;
    const glm::vec3 p = glm::cross(dir, e2);
    const float det = glm::dot(e1, p);
    if (det == 0.0f) return false;
    const float inv_det = 1.0f / det;
    const glm::vec3 s = origin - v0;
    u = glm::dot(s, p) * inv_det;
    if (!(u >= 0.0f && u <= 1.0f)) return false;
    const glm::vec3 q = glm::cross(s, e1);
    v = glm::dot(dir, q) * inv_det;
    if (!(v >= 0.0f && u + v <= 1.0f)) return false;
    t = glm::dot(e2, q) * inv_det;
    return t > tmin && t < tmax;
}

// The hit rule everywhere (see the top of this file): Moller-Trumbore, then the segment
// [tmin, t] must touch the triangle's padded box. Callers that keep the closest hit check
// is_closer() between the two steps, so the box test runs only for would-be winners.
inline bool confirm_triangle_hit(const glm::vec3& origin, const glm::vec3& inv_dir, float tmin,
                                 float t, const glm::vec3& v0, const glm::vec3& v1,
                                 const glm::vec3& v2) {
    const Aabb box = pad_box(Aabb::of_triangle(v0, v1, v2));
    return hit_box(box.lo, box.hi, origin, inv_dir, tmin, t);
}

// The closest-hit rule everywhere: smaller t wins, equal t goes to the smaller original id.
inline bool is_closer(float t, std::int32_t id, const Hit& best) {
    return t < best.t || (t == best.t && id < best.triangle);
}
// Across instances, equal t goes to the smaller (instance, original id) pair: the order of
// the flattened copy's ids. With instance -1 throughout (one level) it is the rule above.
inline bool is_closer(float t, std::int32_t instance, std::int32_t id, const InstanceHit& best) {
    return t < best.t || (t == best.t && (instance < best.instance ||
                                          (instance == best.instance && id < best.triangle)));
}

}  // namespace glslppm
