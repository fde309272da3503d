#include "bvh/traverse_cpu.h"

#include <bit>

namespace glslppm {
namespace {

inline std::int32_t float_bits(float f) { return std::bit_cast<std::int32_t>(f); }

// The link set for this ray: one of six for the MTBVH, the only one for the TBVH.
inline const glm::ivec2* links_for(const PackedBvh& bvh, const glm::vec3& dir) {
    const int order = bvh.order_count == kMtbvhOrderCount ? select_order(dir) : 0;
    return bvh.links.data() + static_cast<std::size_t>(order) * bvh.node_count;
}

}  // namespace

Hit closest_hit(const PackedBvh& bvh, const Ray& ray, TraversalCounts* counts) {
    Hit best;
    best.t = ray.tmax;
    if (bvh.node_count == 0) return best;
    const glm::vec3 inv_dir = safe_inverse_dir(ray.dir);
    const glm::ivec2* links = links_for(bvh, ray.dir);
    std::int32_t node = 0;
    while (node != -1) {
        const glm::vec4 lo = bvh.nodes[2 * node];
        const glm::vec4 hi = bvh.nodes[2 * node + 1];
        if (counts) ++counts->nodes_visited;
        // Inclusive against the best t so far: an equal-t hit may still win on its id.
        if (hit_box(glm::vec3(lo), glm::vec3(hi), ray.origin, inv_dir, ray.tmin, best.t)) {
            const std::int32_t count = float_bits(hi.w);
            const std::int32_t first = float_bits(lo.w);
            for (std::int32_t i = first; i < first + count; ++i) {
                const glm::vec4 a = bvh.triangles[3 * i];
                const glm::vec4 b = bvh.triangles[3 * i + 1];
                const glm::vec4 c = bvh.triangles[3 * i + 2];
                if (counts) ++counts->triangles_tested;
                float t, u, v;
                if (intersect_triangle(ray.origin, ray.dir, ray.tmin, ray.tmax, glm::vec3(a),
                                       glm::vec3(b), glm::vec3(c), t, u, v)) {
                    const std::int32_t id = float_bits(b.w);
                    if (is_closer(t, id, best) &&
                        confirm_triangle_hit(ray.origin, inv_dir, ray.tmin, t, glm::vec3(a),
                                             glm::vec3(b), glm::vec3(c)))
                        best = Hit{t, u, v, id};
                }
            }
            node = links[node].x;
        } else {
            node = links[node].y;
        }
    }
    return best;
}

bool any_hit(const PackedBvh& bvh, const Ray& ray, TraversalCounts* counts) {
    if (bvh.node_count == 0) return false;
    const glm::vec3 inv_dir = safe_inverse_dir(ray.dir);
    const glm::ivec2* links = links_for(bvh, ray.dir);
    std::int32_t node = 0;
    while (node != -1) {
        const glm::vec4 lo = bvh.nodes[2 * node];
        const glm::vec4 hi = bvh.nodes[2 * node + 1];
        if (counts) ++counts->nodes_visited;
        if (hit_box(glm::vec3(lo), glm::vec3(hi), ray.origin, inv_dir, ray.tmin, ray.tmax)) {
            const std::int32_t count = float_bits(hi.w);
            const std::int32_t first = float_bits(lo.w);
            for (std::int32_t i = first; i < first + count; ++i) {
                if (counts) ++counts->triangles_tested;
                const glm::vec3 a(bvh.triangles[3 * i]);
                const glm::vec3 b(bvh.triangles[3 * i + 1]);
                const glm::vec3 c(bvh.triangles[3 * i + 2]);
                float t, u, v;
                if (intersect_triangle(ray.origin, ray.dir, ray.tmin, ray.tmax, a, b, c, t, u, v) &&
                    confirm_triangle_hit(ray.origin, inv_dir, ray.tmin, t, a, b, c))
                    return true;
            }
            node = links[node].x;
        } else {
            node = links[node].y;
        }
    }
    return false;
}

Hit closest_hit_brute_force(const ValidMesh& mesh, const Ray& ray) {
    Hit best;
    best.t = ray.tmax;
    const glm::vec3 inv_dir = safe_inverse_dir(ray.dir);
    for (const std::uint32_t id : mesh.kept) {
        const glm::uvec3 tri = mesh.view.triangles[id];
        const glm::vec3& a = mesh.view.positions[tri.x];
        const glm::vec3& b = mesh.view.positions[tri.y];
        const glm::vec3& c = mesh.view.positions[tri.z];
        float t, u, v;
        if (intersect_triangle(ray.origin, ray.dir, ray.tmin, ray.tmax, a, b, c, t, u, v) &&
            is_closer(t, static_cast<std::int32_t>(id), best) &&
            confirm_triangle_hit(ray.origin, inv_dir, ray.tmin, t, a, b, c))
            best = Hit{t, u, v, static_cast<std::int32_t>(id)};
    }
    return best;
}

bool any_hit_brute_force(const ValidMesh& mesh, const Ray& ray) {
    const glm::vec3 inv_dir = safe_inverse_dir(ray.dir);
    for (const std::uint32_t id : mesh.kept) {
        const glm::uvec3 tri = mesh.view.triangles[id];
        const glm::vec3& a = mesh.view.positions[tri.x];
        const glm::vec3& b = mesh.view.positions[tri.y];
        const glm::vec3& c = mesh.view.positions[tri.z];
        float t, u, v;
        if (intersect_triangle(ray.origin, ray.dir, ray.tmin, ray.tmax, a, b, c, t, u, v) &&
            confirm_triangle_hit(ray.origin, inv_dir, ray.tmin, t, a, b, c))
            return true;
    }
    return false;
}

}  // namespace glslppm
