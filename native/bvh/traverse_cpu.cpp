#include "bvh/traverse_cpu.h"

#include <bit>

#include "bvh/two_level_bvh.h"

namespace glslppm {
namespace {

inline std::int32_t float_bits(float f) { return std::bit_cast<std::int32_t>(f); }

// The arrays one walk reads, in the layout of packed_bvh.h (one level) or two_level_bvh.h.
struct BvhArrays {
    const glm::vec4* nodes = nullptr;
    const glm::ivec2* links = nullptr;
    const glm::vec4* triangles = nullptr;
    const glm::vec4* instances = nullptr;  // the instance records; null for one level
    std::int32_t node_count = 0;           // of the tree at node 0: the only one, or the top
    int order_count = kMtbvhOrderCount;    // 6: MTBVH, 1: TBVH
};

// Where a ray's links of one tree start, so that its (hit, miss) pair of node n is
// links[link_base + n]: the tree's first link, plus the ray's order times its node count
// (its six link sets lie one after another), less its root (node indices are absolute).
inline std::int32_t tree_link_base(std::int32_t root, std::int32_t count, std::int32_t first_link,
                                   int order_count, const glm::vec3& dir) {
    const int order = order_count == kMtbvhOrderCount ? select_order(dir) : 0;
    return first_link + order * count - root;
}

// The one stackless walk (Hachisuka 2015, Figure 3) of a one-level tree and of both levels of
// a two-level one; mirrors bvh_walk in shaders/common/mtbvh.glsl line by line. In a
// two-level tree a top leaf moves the ray into its instance's space and the walk goes on in
// that instance's tree, along the moved ray's own link set; when that tree ends it resumes
// at the top leaf's hit link: the one node index saved across the levels. kFirstHit: stop
// at the first accepted hit (any_hit). Until a hit is accepted best.t is the ray's tmax and
// is_closer holds for every triangle hit, so the two modes visit the same nodes up to there.
template <bool kFirstHit>
InstanceHit walk(const BvhArrays& bvh, const Ray& world, TraversalCounts* counts) {
    InstanceHit best;
    best.t = world.tmax;
    if (bvh.node_count == 0) return best;
    const bool two_level = bvh.instances != nullptr;
    const glm::vec3 world_inv_dir = safe_inverse_dir(world.dir);
    const std::int32_t world_link_base =
        tree_link_base(0, bvh.node_count, 0, bvh.order_count, world.dir);
    Ray ray = world;
    glm::vec3 inv_dir = world_inv_dir;
    std::int32_t link_base = world_link_base;
    std::int32_t instance = -1;  // whose tree the walk is in; -1: the top (or only) tree
    std::int32_t resume = -1;    // the top node to go on from when the instance's tree ends
    std::int32_t node = 0;
    while (node != -1) {
        const glm::vec4 lo = bvh.nodes[2 * node];
        const glm::vec4 hi = bvh.nodes[2 * node + 1];
        if (counts) ++counts->nodes_visited;
        // Inclusive against the best t so far: an equal-t hit may still win on its id (until
        // an any-hit walk accepts one, best.t is the ray's tmax).
        if (hit_box(glm::vec3(lo), glm::vec3(hi), ray.origin, inv_dir, ray.tmin,
                    kFirstHit ? ray.tmax : best.t)) {
            const std::int32_t count = float_bits(hi.w);
            const std::int32_t first = float_bits(lo.w);
            if (two_level && instance < 0 && count > 0) {  // a top leaf: lo.w is its instance
                const glm::vec4* record = &bvh.instances[kInstanceRecordVec4 * first];
                const glm::ivec4 tree(float_bits(record[6].x), float_bits(record[6].y),
                                      float_bits(record[6].z), float_bits(record[6].w));
                instance = first;
                resume = bvh.links[link_base + node].x;
                ray = ray_to_instance(record, world);
                inv_dir = safe_inverse_dir(ray.dir);
                link_base = tree_link_base(tree.x, tree.y, tree.z, kMtbvhOrderCount, ray.dir);
                node = tree.y > 0 ? tree.x : -1;
            } else {
                for (std::int32_t i = first; i < first + count; ++i) {
                    const glm::vec3 a(bvh.triangles[3 * i]);
                    const glm::vec4 b = bvh.triangles[3 * i + 1];
                    const glm::vec3 c(bvh.triangles[3 * i + 2]);
                    if (counts) ++counts->triangles_tested;
                    float t, u, v;
                    if (intersect_triangle(ray.origin, ray.dir, ray.tmin, ray.tmax, a, glm::vec3(b),
                                           c, t, u, v)) {
                        const std::int32_t id = float_bits(b.w);
                        if ((kFirstHit || is_closer(t, instance, id, best)) &&
                            confirm_triangle_hit(ray.origin, inv_dir, ray.tmin, t, a, glm::vec3(b),
                                                 c)) {
                            best = InstanceHit{t, u, v, instance, id};
                            if (kFirstHit) return best;
                        }
                    }
                }
                node = bvh.links[link_base + node].x;
            }
        } else {
            node = bvh.links[link_base + node].y;
        }
        if (node == -1 && instance >= 0) {  // the instance's tree is done: back to the top
            instance = -1;
            ray = world;
            inv_dir = world_inv_dir;
            link_base = world_link_base;
            node = resume;
        }
    }
    return best;
}

BvhArrays arrays_of(const PackedBvh& bvh) {
    return {bvh.nodes.data(),
            bvh.links.data(),
            bvh.triangles.data(),
            nullptr,
            static_cast<std::int32_t>(bvh.node_count),
            bvh.order_count};
}

BvhArrays arrays_of(const TwoLevelBvh& bvh) {
    return {bvh.nodes.data(),
            bvh.links.data(),
            bvh.triangles.data(),
            bvh.instances.data(),
            static_cast<std::int32_t>(bvh.top_node_count),
            kMtbvhOrderCount};
}

// Every kept triangle of the mesh in id order, for the ray in the mesh's space.
template <bool kFirstHit>
void brute_force_mesh(const ValidMesh& mesh, std::int32_t instance, const Ray& ray,
                      InstanceHit& best) {
    const glm::vec3 inv_dir = safe_inverse_dir(ray.dir);
    for (const std::uint32_t kept : mesh.kept) {
        const auto id = static_cast<std::int32_t>(kept);
        const glm::uvec3 tri = mesh.view.triangles[kept];
        const glm::vec3& a = mesh.view.positions[tri.x];
        const glm::vec3& b = mesh.view.positions[tri.y];
        const glm::vec3& c = mesh.view.positions[tri.z];
        float t, u, v;
        if (intersect_triangle(ray.origin, ray.dir, ray.tmin, ray.tmax, a, b, c, t, u, v) &&
            (kFirstHit || is_closer(t, instance, id, best)) &&
            confirm_triangle_hit(ray.origin, inv_dir, ray.tmin, t, a, b, c)) {
            best = InstanceHit{t, u, v, instance, id};
            if (kFirstHit) return;
        }
    }
}

template <bool kFirstHit>
InstanceHit brute_force_instances(const TwoLevelBvh& bvh, std::span<const ValidMesh> meshes,
                                  std::span<const Instance> instances, const Ray& ray) {
    InstanceHit best;
    best.t = ray.tmax;
    for (std::size_t i = 0; i < instances.size(); ++i) {
        const auto instance = static_cast<std::int32_t>(i);
        brute_force_mesh<kFirstHit>(meshes[instances[i].mesh], instance,
                                    ray_to_instance(bvh, instance, ray), best);
        if (kFirstHit && best.triangle >= 0) break;
    }
    return best;
}

Hit one_level(const InstanceHit& h) { return Hit{h.t, h.u, h.v, h.triangle}; }

}  // namespace

Ray ray_to_instance(const glm::vec4* record, const Ray& world) {
    const glm::vec3 r0(record[0]), r1(record[1]), r2(record[2]);
    const glm::vec3 p = world.origin - glm::vec3(record[0].w, record[1].w, record[2].w);
    Ray r;
    r.origin = glm::vec3(glm::dot(r0, p), glm::dot(r1, p), glm::dot(r2, p));
    r.dir = glm::vec3(glm::dot(r0, world.dir), glm::dot(r1, world.dir), glm::dot(r2, world.dir));
    r.tmin = world.tmin;
    r.tmax = world.tmax;
    return r;
}

Ray ray_to_instance(const TwoLevelBvh& bvh, std::int32_t instance, const Ray& world) {
    return ray_to_instance(&bvh.instances[kInstanceRecordVec4 * instance], world);
}

Hit closest_hit(const PackedBvh& bvh, const Ray& ray, TraversalCounts* counts) {
    return one_level(walk<false>(arrays_of(bvh), ray, counts));
}

bool any_hit(const PackedBvh& bvh, const Ray& ray, TraversalCounts* counts) {
    return walk<true>(arrays_of(bvh), ray, counts).triangle >= 0;
}

InstanceHit closest_hit(const TwoLevelBvh& bvh, const Ray& ray, TraversalCounts* counts) {
    return walk<false>(arrays_of(bvh), ray, counts);
}

bool any_hit(const TwoLevelBvh& bvh, const Ray& ray, TraversalCounts* counts) {
    return walk<true>(arrays_of(bvh), ray, counts).triangle >= 0;
}

Hit closest_hit_brute_force(const ValidMesh& mesh, const Ray& ray) {
    InstanceHit best;
    best.t = ray.tmax;
    brute_force_mesh<false>(mesh, -1, ray, best);
    return one_level(best);
}

bool any_hit_brute_force(const ValidMesh& mesh, const Ray& ray) {
    InstanceHit best;
    best.t = ray.tmax;
    brute_force_mesh<true>(mesh, -1, ray, best);
    return best.triangle >= 0;
}

InstanceHit closest_hit_brute_force(const TwoLevelBvh& bvh, std::span<const ValidMesh> meshes,
                                    std::span<const Instance> instances, const Ray& ray) {
    return brute_force_instances<false>(bvh, meshes, instances, ray);
}

bool any_hit_brute_force(const TwoLevelBvh& bvh, std::span<const ValidMesh> meshes,
                         std::span<const Instance> instances, const Ray& ray) {
    return brute_force_instances<true>(bvh, meshes, instances, ray).triangle >= 0;
}

}  // namespace glslppm
