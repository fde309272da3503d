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

// The instance's record (layout in two_level_bvh.h).
void write_record(glm::vec4* rec, const glm::mat4& m, glm::ivec4 bases, std::uint32_t mesh) {
    rec[6] = glm::vec4(int_bits(bases.x), int_bits(bases.y), int_bits(bases.z), int_bits(bases.w));
    rec[7] = glm::vec4(int_bits(static_cast<std::int32_t>(mesh)), 0.0f, 0.0f, 0.0f);
    write_instance_transform(rec, m);
}

}  // namespace

// A^-1 inverted in double, then rounded.
void write_instance_transform(glm::vec4* rec, const glm::mat4& m) {
    const glm::mat3 a(m);
    const glm::dmat3 a_inv = glm::inverse(glm::dmat3(a));
    const glm::vec3 t(m[3]);
    for (int k = 0; k < 3; ++k) {
        rec[k] = glm::vec4(static_cast<float>(a_inv[0][k]), static_cast<float>(a_inv[1][k]),
                           static_cast<float>(a_inv[2][k]), t[k]);
        rec[3 + k] = glm::vec4(a[0][k], a[1][k], a[2][k], t[k]);
    }
    rec[7].y = glm::determinant(glm::dmat3(a)) < 0.0 ? -1.0f : 1.0f;
}

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
    bool normals = false, uvs = false, colors = false;
    for (const PackedBvh& b : bottoms) {
        normals |= !b.normals.empty();
        uvs |= !b.uvs.empty();
        colors |= !b.colors.empty();
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
    out.top_children.assign(top.nodes.size(), glm::ivec2(-1));
    for (std::size_t i = top.nodes.size(); i-- > 0;) {
        const BvhNode& node = top.nodes[i];
        std::int32_t instance = 0;
        if (!node.is_leaf())
            out.top_children[i] = glm::ivec2(static_cast<std::int32_t>(node.left),
                                             static_cast<std::int32_t>(node.right));
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
    if (colors) out.colors.reserve(3 * tri_total);
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
        if (colors) {  // a mesh without colours is white: its materials' colours unchanged
            if (b.colors.empty())
                out.colors.resize(out.colors.size() + 3 * b.triangle_count, glm::vec4(1.0f));
            else
                out.colors.insert(out.colors.end(), b.colors.begin(), b.colors.end());
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
                     out.colors.size() + out.instances.size()) *
                        sizeof(glm::vec4) +
                    out.links.size() * sizeof(glm::ivec2);
    return out;
}

}  // namespace glslppm
