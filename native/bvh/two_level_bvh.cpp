#include "bvh/two_level_bvh.h"

#include <bit>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "bvh/thread_mtbvh.h"

namespace glslppm {
namespace {

inline std::int32_t float_bits(float f) { return std::bit_cast<std::int32_t>(f); }
inline float int_bits(std::int32_t i) { return std::bit_cast<float>(i); }

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void check_transform(const glm::mat4& m, std::size_t index) {
    const std::string name = "instances[" + std::to_string(index) + "]";
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(m[c][r]))
                throw std::invalid_argument(name + ".to_world is not finite");
    if (m[0][3] != 0.0f || m[1][3] != 0.0f || m[2][3] != 0.0f || m[3][3] != 1.0f)
        throw std::invalid_argument(name + ".to_world is not affine (bottom row must be 0 0 0 1)");
    const double det = glm::determinant(glm::dmat3(glm::mat3(m)));
    if (!(std::abs(det) > 0.0) || !std::isfinite(1.0 / det))
        throw std::invalid_argument(name + ".to_world is singular (determinant " +
                                    std::to_string(det) + ")");
}

// The instance's record (layout in two_level_bvh.h); A^-1 inverted in double, then rounded.
void write_record(glm::vec4* rec, const glm::mat4& m, glm::ivec4 bases, std::uint32_t mesh) {
    const glm::mat3 a(m);
    const glm::dmat3 a_inv = glm::inverse(glm::dmat3(a));
    const glm::vec3 t(m[3]);
    for (int k = 0; k < 3; ++k) {
        rec[k] = glm::vec4(static_cast<float>(a_inv[0][k]), static_cast<float>(a_inv[1][k]),
                           static_cast<float>(a_inv[2][k]), t[k]);
        rec[3 + k] = glm::vec4(a[0][k], a[1][k], a[2][k], t[k]);
    }
    rec[6] = glm::vec4(int_bits(bases.x), int_bits(bases.y), int_bits(bases.z), int_bits(bases.w));
    const float sign = glm::determinant(glm::dmat3(a)) < 0.0 ? -1.0f : 1.0f;
    rec[7] = glm::vec4(int_bits(static_cast<std::int32_t>(mesh)), sign, 0.0f, 0.0f);
}

inline bool is_closer(float t, std::int32_t instance, std::int32_t id, const InstanceHit& best) {
    return t < best.t || (t == best.t && (instance < best.instance ||
                                          (instance == best.instance && id < best.triangle)));
}

// The bottom walk of one instance: the mesh's own link set for the moved ray, starting at
// its root; updates `best` in place. Mirrors bvh_walk_instance in mtbvh_instances.glsl.
void walk_instance(const TwoLevelBvh& bvh, std::int32_t instance, const Ray& ray, InstanceHit& best,
                   TraversalCounts* counts) {
    const Ray r = ray_to_instance(bvh, instance, ray);
    const glm::vec4 bases = bvh.instances[kInstanceRecordVec4 * instance + 6];
    const std::int32_t root = float_bits(bases.x), count = float_bits(bases.y);
    const std::int32_t link_base =
        float_bits(bases.z) + select_order(r.dir) * count - root;  // links[link_base + node]
    const glm::vec3 inv_dir = safe_inverse_dir(r.dir);
    std::int32_t node = count > 0 ? root : -1;
    while (node != -1) {
        const glm::vec4 lo = bvh.nodes[2 * node];
        const glm::vec4 hi = bvh.nodes[2 * node + 1];
        if (counts) ++counts->nodes_visited;
        if (hit_box(glm::vec3(lo), glm::vec3(hi), r.origin, inv_dir, r.tmin, best.t)) {
            const std::int32_t n = float_bits(hi.w);
            const std::int32_t first = float_bits(lo.w);
            for (std::int32_t i = first; i < first + n; ++i) {
                const glm::vec4 a = bvh.triangles[3 * i];
                const glm::vec4 b = bvh.triangles[3 * i + 1];
                const glm::vec4 c = bvh.triangles[3 * i + 2];
                if (counts) ++counts->triangles_tested;
                float t, u, v;
                if (intersect_triangle(r.origin, r.dir, r.tmin, r.tmax, glm::vec3(a), glm::vec3(b),
                                       glm::vec3(c), t, u, v)) {
                    const std::int32_t id = float_bits(b.w);
                    if (is_closer(t, instance, id, best) &&
                        confirm_triangle_hit(r.origin, inv_dir, r.tmin, t, glm::vec3(a),
                                             glm::vec3(b), glm::vec3(c)))
                        best = InstanceHit{t, u, v, instance, id};
                }
            }
            node = bvh.links[link_base + node].x;
        } else {
            node = bvh.links[link_base + node].y;
        }
    }
}

bool walk_instance_any(const TwoLevelBvh& bvh, std::int32_t instance, const Ray& ray,
                       TraversalCounts* counts) {
    const Ray r = ray_to_instance(bvh, instance, ray);
    const glm::vec4 bases = bvh.instances[kInstanceRecordVec4 * instance + 6];
    const std::int32_t root = float_bits(bases.x), count = float_bits(bases.y);
    const std::int32_t link_base = float_bits(bases.z) + select_order(r.dir) * count - root;
    const glm::vec3 inv_dir = safe_inverse_dir(r.dir);
    std::int32_t node = count > 0 ? root : -1;
    while (node != -1) {
        const glm::vec4 lo = bvh.nodes[2 * node];
        const glm::vec4 hi = bvh.nodes[2 * node + 1];
        if (counts) ++counts->nodes_visited;
        if (hit_box(glm::vec3(lo), glm::vec3(hi), r.origin, inv_dir, r.tmin, r.tmax)) {
            const std::int32_t n = float_bits(hi.w);
            const std::int32_t first = float_bits(lo.w);
            for (std::int32_t i = first; i < first + n; ++i) {
                if (counts) ++counts->triangles_tested;
                const glm::vec3 a(bvh.triangles[3 * i]);
                const glm::vec3 b(bvh.triangles[3 * i + 1]);
                const glm::vec3 c(bvh.triangles[3 * i + 2]);
                float t, u, v;
                if (intersect_triangle(r.origin, r.dir, r.tmin, r.tmax, a, b, c, t, u, v) &&
                    confirm_triangle_hit(r.origin, inv_dir, r.tmin, t, a, b, c))
                    return true;
            }
            node = bvh.links[link_base + node].x;
        } else {
            node = bvh.links[link_base + node].y;
        }
    }
    return false;
}

}  // namespace

Aabb instance_world_box(const glm::vec3& lo, const glm::vec3& hi, const glm::mat4& to_world) {
    const glm::dmat4 m(to_world);
    glm::dvec3 wlo(std::numeric_limits<double>::infinity()), whi(-wlo);
    for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec4 p((corner & 1) ? hi.x : lo.x, (corner & 2) ? hi.y : lo.y,
                           (corner & 4) ? hi.z : lo.z, 1.0);
        const glm::dvec3 w(m * p);
        wlo = glm::min(wlo, w);
        whi = glm::max(whi, w);
    }
    Aabb box;
    for (int k = 0; k < 3; ++k) {
        box.lo[k] = std::nextafter(static_cast<float>(wlo[k]), -INFINITY);
        box.hi[k] = std::nextafter(static_cast<float>(whi[k]), INFINITY);
    }
    const float pad = box.magnitude() * kInstanceBoxPadRelative;
    return Aabb{box.lo - pad, box.hi + pad};
}

TwoLevelBvh build_two_level_bvh(std::span<const ValidMesh> meshes,
                                std::span<const Instance> instances,
                                const BvhBuildOptions& options) {
    for (std::size_t i = 0; i < instances.size(); ++i) {
        if (instances[i].mesh >= meshes.size())
            throw std::invalid_argument("instances[" + std::to_string(i) + "].mesh is " +
                                        std::to_string(instances[i].mesh) + " but there are " +
                                        std::to_string(meshes.size()) + " meshes");
        check_transform(instances[i].to_world, i);
    }
    const auto start = std::chrono::steady_clock::now();
    std::vector<PackedBvh> bottoms;
    bottoms.reserve(meshes.size());
    for (const ValidMesh& mesh : meshes)
        bottoms.push_back(build_packed_bvh(mesh, options, kMtbvhOrderCount));
    const double bottom_seconds = seconds_since(start);
    TwoLevelBvh out = build_two_level_bvh(bottoms, instances, options);
    out.stats.bottom_seconds = bottom_seconds;
    return out;
}

TwoLevelBvh build_two_level_bvh(std::span<const PackedBvh> bottoms,
                                std::span<const Instance> instances,
                                const BvhBuildOptions& options) {
    for (std::size_t i = 0; i < instances.size(); ++i) {
        if (instances[i].mesh >= bottoms.size())
            throw std::invalid_argument("instances[" + std::to_string(i) + "].mesh is " +
                                        std::to_string(instances[i].mesh) + " but there are " +
                                        std::to_string(bottoms.size()) + " meshes");
        check_transform(instances[i].to_world, i);
    }
    for (const PackedBvh& b : bottoms)
        if (b.node_count > 0 && b.order_count != kMtbvhOrderCount)
            throw std::invalid_argument("a two-level MTBVH's meshes need six link orders");
    TwoLevelBvh out;
    TwoLevelStats& s = out.stats;
    s.meshes = bottoms.size();
    s.instances = instances.size();
    bool normals = false, uvs = false;
    for (const PackedBvh& b : bottoms) {
        normals |= !b.normals.empty();
        uvs |= !b.uvs.empty();
        s.mesh_triangles += b.triangle_count;
    }
    const auto start = std::chrono::steady_clock::now();

    // The top tree: one leaf per instance, over its world box.
    // Instances of empty meshes can never be hit and stay out of the top tree.
    std::vector<Aabb> boxes;
    std::vector<std::int32_t> placed;
    for (std::size_t i = 0; i < instances.size(); ++i) {
        throw_if_cancelled(options.cancel);
        const PackedBvh& b = bottoms[instances[i].mesh];
        s.instanced_triangles += b.triangle_count;
        if (b.node_count == 0) continue;
        boxes.push_back(instance_world_box(glm::vec3(b.nodes[0]), glm::vec3(b.nodes[1]),
                                           instances[i].to_world));
        placed.push_back(static_cast<std::int32_t>(i));
    }
    BvhBuildOptions top_options = options;
    top_options.leaf_size = 1;
    const Bvh top = build_sah_bvh(boxes, top_options);
    ThreadedBvh threaded = thread_bvh(top, kMtbvhOrderCount, options.parallel, options.cancel);
    out.top_node_count = threaded.node_count;
    s.top_nodes = top.nodes.size();

    // Assemble: top nodes first. Top boxes are the instances' world boxes (already padded),
    // inner ones the unions of their children's, as pack_bvh does for triangles.
    std::size_t node_total = top.nodes.size(), tri_total = 0;
    for (const PackedBvh& b : bottoms) {
        node_total += b.node_count;
        tri_total += b.triangle_count;
    }
    out.nodes.resize(2 * node_total);
    out.links.reserve(kMtbvhOrderCount * node_total);
    std::vector<Aabb> top_boxes(top.nodes.size());
    for (std::size_t i = top.nodes.size(); i-- > 0;) {
        const BvhNode& node = top.nodes[i];
        std::int32_t instance = 0;
        if (node.is_leaf()) {
            const std::uint32_t box = top.triangles[node.first];
            instance = placed[box];
            top_boxes[i] = boxes[box];
        } else {
            top_boxes[i] = top_boxes[node.left];
            top_boxes[i].grow(top_boxes[node.right]);
        }
        out.nodes[2 * i] = glm::vec4(top_boxes[i].lo, int_bits(instance));
        out.nodes[2 * i + 1] =
            glm::vec4(top_boxes[i].hi, int_bits(static_cast<std::int32_t>(node.count)));
    }
    out.links = std::move(threaded.links);

    std::vector<glm::ivec4> mesh_bases(bottoms.size());
    std::size_t node_base = top.nodes.size(), tri_base = 0;
    out.triangles.reserve(3 * tri_total);
    if (normals) out.normals.reserve(3 * tri_total);
    if (uvs) out.uvs.reserve(2 * tri_total);
    for (std::size_t m = 0; m < bottoms.size(); ++m) {
        throw_if_cancelled(options.cancel);
        const PackedBvh& b = bottoms[m];
        const auto nb = static_cast<std::int32_t>(node_base);
        mesh_bases[m] = glm::ivec4(nb, static_cast<std::int32_t>(b.node_count),
                                   static_cast<std::int32_t>(out.links.size()), 0);
        for (std::uint32_t i = 0; i < b.node_count; ++i) {
            glm::vec4 lo = b.nodes[2 * i];
            const glm::vec4 hi = b.nodes[2 * i + 1];
            if (float_bits(hi.w) > 0)
                lo.w = int_bits(float_bits(lo.w) + static_cast<std::int32_t>(tri_base));
            out.nodes[2 * (node_base + i)] = lo;
            out.nodes[2 * (node_base + i) + 1] = hi;
        }
        for (const glm::ivec2& l : b.links)
            out.links.emplace_back(l.x < 0 ? -1 : l.x + nb, l.y < 0 ? -1 : l.y + nb);
        out.triangles.insert(out.triangles.end(), b.triangles.begin(), b.triangles.end());
        if (normals) {
            if (b.normals.empty())
                out.normals.resize(out.normals.size() + 3 * b.triangle_count, glm::vec4(0.0f));
            else
                out.normals.insert(out.normals.end(), b.normals.begin(), b.normals.end());
        }
        if (uvs) {
            if (b.uvs.empty())
                out.uvs.resize(out.uvs.size() + 2 * b.triangle_count, glm::vec4(0.0f));
            else
                out.uvs.insert(out.uvs.end(), b.uvs.begin(), b.uvs.end());
        }
        node_base += b.node_count;
        tri_base += b.triangle_count;
        s.bottom_nodes += b.node_count;
    }

    out.instances.resize(kInstanceRecordVec4 * instances.size());
    for (std::size_t i = 0; i < instances.size(); ++i) {
        const Instance& inst = instances[i];
        glm::ivec4 bases = mesh_bases[inst.mesh];
        bases.w = static_cast<std::int32_t>(inst.material_offset);
        write_record(&out.instances[kInstanceRecordVec4 * i], inst.to_world, bases, inst.mesh);
    }
    s.top_seconds = seconds_since(start);
    s.bytes_total = (out.nodes.size() + out.triangles.size() + out.normals.size() + out.uvs.size() +
                     out.instances.size()) *
                        sizeof(glm::vec4) +
                    out.links.size() * sizeof(glm::ivec2);
    return out;
}

Ray ray_to_instance(const TwoLevelBvh& bvh, std::int32_t instance, const Ray& world) {
    const glm::vec4* rec = &bvh.instances[kInstanceRecordVec4 * instance];
    const glm::vec3 r0(rec[0]), r1(rec[1]), r2(rec[2]);
    const glm::vec3 p = world.origin - glm::vec3(rec[0].w, rec[1].w, rec[2].w);
    Ray r;
    r.origin = glm::vec3(glm::dot(r0, p), glm::dot(r1, p), glm::dot(r2, p));
    r.dir = glm::vec3(glm::dot(r0, world.dir), glm::dot(r1, world.dir), glm::dot(r2, world.dir));
    r.tmin = world.tmin;
    r.tmax = world.tmax;
    return r;
}

InstanceHit closest_hit(const TwoLevelBvh& bvh, const Ray& ray, TraversalCounts* counts) {
    InstanceHit best;
    best.t = ray.tmax;
    if (bvh.top_node_count == 0) return best;
    const glm::vec3 inv_dir = safe_inverse_dir(ray.dir);
    const glm::ivec2* links =
        bvh.links.data() + static_cast<std::size_t>(select_order(ray.dir)) * bvh.top_node_count;
    std::int32_t node = 0;
    while (node != -1) {
        const glm::vec4 lo = bvh.nodes[2 * node];
        const glm::vec4 hi = bvh.nodes[2 * node + 1];
        if (counts) ++counts->nodes_visited;
        if (hit_box(glm::vec3(lo), glm::vec3(hi), ray.origin, inv_dir, ray.tmin, best.t)) {
            // A top leaf: the instance's own walk; then on along the saved top link.
            if (float_bits(hi.w) > 0) walk_instance(bvh, float_bits(lo.w), ray, best, counts);
            node = links[node].x;
        } else {
            node = links[node].y;
        }
    }
    return best;
}

bool any_hit(const TwoLevelBvh& bvh, const Ray& ray, TraversalCounts* counts) {
    if (bvh.top_node_count == 0) return false;
    const glm::vec3 inv_dir = safe_inverse_dir(ray.dir);
    const glm::ivec2* links =
        bvh.links.data() + static_cast<std::size_t>(select_order(ray.dir)) * bvh.top_node_count;
    std::int32_t node = 0;
    while (node != -1) {
        const glm::vec4 lo = bvh.nodes[2 * node];
        const glm::vec4 hi = bvh.nodes[2 * node + 1];
        if (counts) ++counts->nodes_visited;
        if (hit_box(glm::vec3(lo), glm::vec3(hi), ray.origin, inv_dir, ray.tmin, ray.tmax)) {
            if (float_bits(hi.w) > 0 && walk_instance_any(bvh, float_bits(lo.w), ray, counts))
                return true;
            node = links[node].x;
        } else {
            node = links[node].y;
        }
    }
    return false;
}

InstanceHit closest_hit_brute_force(const TwoLevelBvh& bvh, std::span<const ValidMesh> meshes,
                                    std::span<const Instance> instances, const Ray& ray) {
    InstanceHit best;
    best.t = ray.tmax;
    for (std::size_t i = 0; i < instances.size(); ++i) {
        const auto instance = static_cast<std::int32_t>(i);
        const Ray r = ray_to_instance(bvh, instance, ray);
        const glm::vec3 inv_dir = safe_inverse_dir(r.dir);
        const ValidMesh& mesh = meshes[instances[i].mesh];
        for (const std::uint32_t id : mesh.kept) {
            const glm::uvec3 tri = mesh.view.triangles[id];
            const glm::vec3& a = mesh.view.positions[tri.x];
            const glm::vec3& b = mesh.view.positions[tri.y];
            const glm::vec3& c = mesh.view.positions[tri.z];
            float t, u, v;
            if (intersect_triangle(r.origin, r.dir, r.tmin, r.tmax, a, b, c, t, u, v) &&
                is_closer(t, instance, static_cast<std::int32_t>(id), best) &&
                confirm_triangle_hit(r.origin, inv_dir, r.tmin, t, a, b, c))
                best = InstanceHit{t, u, v, instance, static_cast<std::int32_t>(id)};
        }
    }
    return best;
}

bool any_hit_brute_force(const TwoLevelBvh& bvh, std::span<const ValidMesh> meshes,
                         std::span<const Instance> instances, const Ray& ray) {
    for (std::size_t i = 0; i < instances.size(); ++i) {
        const Ray r = ray_to_instance(bvh, static_cast<std::int32_t>(i), ray);
        const glm::vec3 inv_dir = safe_inverse_dir(r.dir);
        const ValidMesh& mesh = meshes[instances[i].mesh];
        for (const std::uint32_t id : mesh.kept) {
            const glm::uvec3 tri = mesh.view.triangles[id];
            const glm::vec3& a = mesh.view.positions[tri.x];
            const glm::vec3& b = mesh.view.positions[tri.y];
            const glm::vec3& c = mesh.view.positions[tri.z];
            float t, u, v;
            if (intersect_triangle(r.origin, r.dir, r.tmin, r.tmax, a, b, c, t, u, v) &&
                confirm_triangle_hit(r.origin, inv_dir, r.tmin, t, a, b, c))
                return true;
        }
    }
    return false;
}

}  // namespace glslppm
