// Motion blur's part of a pass (render/motion.h): at the pass's time, the camera goes into
// the frame's constants (uploaded with them by begin_pass) and each moving instance's
// transform into its record; the top level of the two-level MTBVH is refitted over the
// moved instances' boxes (its topology, built at the frame's time, stays) and its nodes and
// the records' range are uploaded. The bottom trees and every other buffer stay.
#include <chrono>

#include "render/pipeline.h"

namespace glslppm {
namespace {

inline std::int32_t float_bits(float f) { return std::bit_cast<std::int32_t>(f); }

// A deforming mesh's bottom tree (the nodes of one mesh lie in preorder, left child first,
// from its root): children per node and the packed triangles' range, and copies.
DeformScratch start_deformation(const TwoLevelBvh& tree, std::uint32_t root,
                                std::uint32_t node_count) {
    DeformScratch d;
    d.root = root;
    d.children.assign(node_count, glm::ivec2(-1));
    d.first_triangle = tree.triangles.size();
    std::vector<std::uint32_t> open;  // inner nodes still waiting for their right child
    for (std::uint32_t j = 0; j < node_count; ++j) {
        if (j > 0) {
            // j is the left child of the node before it, if that one is inner; else the right
            // child of the innermost inner node still waiting for one.
            const std::uint32_t prev = j - 1;
            if (float_bits(tree.nodes[2 * (root + prev) + 1].w) == 0) {
                d.children[prev].x = static_cast<std::int32_t>(j);
            } else {
                d.children[open.back()].y = static_cast<std::int32_t>(j);
                open.pop_back();
            }
        }
        const std::int32_t count = float_bits(tree.nodes[2 * (root + j) + 1].w);
        if (count == 0) {
            open.push_back(j);
        } else {
            const auto first = static_cast<std::size_t>(float_bits(tree.nodes[2 * (root + j)].w));
            d.first_triangle = std::min(d.first_triangle, first);
            d.end_triangle = std::max(d.end_triangle, first + static_cast<std::size_t>(count));
        }
    }
    d.nodes.assign(tree.nodes.begin() + 2 * root, tree.nodes.begin() + 2 * (root + node_count));
    d.triangles.assign(tree.triangles.begin() + 3 * d.first_triangle,
                       tree.triangles.begin() + 3 * d.end_triangle);
    if (!tree.normals.empty())
        d.normals.assign(tree.normals.begin() + 3 * d.first_triangle,
                         tree.normals.begin() + 3 * d.end_triangle);
    return d;
}

// The copies and the map from records to top leaves, once per worker.
void start_scratch(MotionScratch& s, const TwoLevelBvh& tree, const MotionPlan& plan) {
    s.top_nodes.assign(tree.nodes.begin(), tree.nodes.begin() + 2 * tree.top_node_count);
    s.records = tree.instances;
    const std::size_t record_count = tree.instances.size() / kInstanceRecordVec4;
    s.leaf_of_instance.assign(record_count, -1);
    for (std::uint32_t i = 0; i < tree.top_node_count; ++i)
        if (tree.top_children[i].x < 0)
            s.leaf_of_instance[static_cast<std::size_t>(float_bits(tree.nodes[2 * i].w))] =
                static_cast<std::int32_t>(i);
    s.first_record = s.records.size();
    s.end_record = 0;
    std::vector<bool> refit(record_count, false);
    for (std::uint32_t instance : plan.instances) {
        const std::size_t record = instance + 1u;  // record 0: the placed-once triangles
        s.first_record = std::min(s.first_record, record);
        s.end_record = std::max(s.end_record, record + 1);
        refit[record] = true;
    }
    for (std::size_t k = 0; k < plan.meshes.size(); ++k) {
        const std::uint32_t mesh = plan.meshes[k].mesh;
        if (s.deformed_of_mesh.size() <= mesh) s.deformed_of_mesh.resize(mesh + 1, -1);
        s.deformed_of_mesh[mesh] = static_cast<std::int32_t>(k);
        s.meshes.emplace_back();
        for (std::size_t r = 1; r < record_count; ++r) {
            const glm::vec4* rec = &s.records[kInstanceRecordVec4 * r];
            // The tree's mesh 0 is the placed-once triangles: the scene's mesh m is its m + 1.
            if (static_cast<std::uint32_t>(float_bits(rec[7].x)) != mesh + 1u) continue;
            refit[r] = true;
            if (s.meshes.back().children.empty())
                s.meshes.back() = start_deformation(
                    tree, static_cast<std::uint32_t>(float_bits(rec[6].x)),
                    static_cast<std::uint32_t>(float_bits(rec[6].y)));
        }
    }
    for (std::size_t r = 0; r < record_count; ++r)
        if (refit[r]) s.refit_records.push_back(r);
}

glm::mat4 record_to_world(const glm::vec4* rec) {
    glm::mat4 m(1.0f);
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) m[c][r] = rec[3 + r][c];
        m[3][r] = rec[3 + r].w;
    }
    return m;
}

}  // namespace

void Renderer::Gpu::move_to_shutter_time(std::uint64_t pass_index) {
    const MotionPlan& plan = *scene.motion;
    const double t = plan.time(settings.seed, pass_index);
    if (plan.camera) camera_frame(plan.camera_at(t), settings, scene.frame);
    if ((plan.instances.empty() && plan.meshes.empty()) || !two_level) return;
    const auto start = std::chrono::steady_clock::now();
    const TwoLevelBvh& tree = *two_level;
    MotionScratch& s = motion;
    if (s.top_nodes.empty()) start_scratch(s, tree, plan);
    deform_meshes(t);
    for (std::size_t k = 0; k < plan.instances.size(); ++k)
        write_instance_transform(&s.records[kInstanceRecordVec4 * (plan.instances[k] + 1u)],
                                 plan.instance_motion[k].at(t));
    // The moved and deformed instances' leaf boxes (instance_world_box: the mesh's root box
    // mapped and padded as the build maps it).
    for (std::size_t record : s.refit_records) {
        const glm::vec4* rec = &s.records[kInstanceRecordVec4 * record];
        const std::int32_t leaf = s.leaf_of_instance[record];
        if (leaf < 0) continue;  // an empty mesh: never in the top tree
        const auto mesh = static_cast<std::size_t>(float_bits(rec[7].x)) - 1u;  // the scene's
        const std::int32_t deformed =
            mesh < s.deformed_of_mesh.size() ? s.deformed_of_mesh[mesh] : -1;
        const auto root = static_cast<std::size_t>(float_bits(rec[6].x));
        const glm::vec4* root_box = deformed >= 0 ? s.meshes[std::size_t(deformed)].nodes.data()
                                                  : &tree.nodes[2 * root];
        const Aabb box = instance_world_box(glm::vec3(root_box[0]), glm::vec3(root_box[1]),
                                            record_to_world(rec));
        s.top_nodes[2 * leaf] = glm::vec4(box.lo, s.top_nodes[2 * leaf].w);
        s.top_nodes[2 * leaf + 1] = glm::vec4(box.hi, s.top_nodes[2 * leaf + 1].w);
    }
    // Refit: children come after their parents, so one backwards sweep.
    for (std::uint32_t i = tree.top_node_count; i-- > 0;) {
        const glm::ivec2 c = tree.top_children[i];
        if (c.x < 0) continue;
        const auto l = static_cast<std::size_t>(c.x), r = static_cast<std::size_t>(c.y);
        const glm::vec3 lo = glm::min(glm::vec3(s.top_nodes[2 * l]), glm::vec3(s.top_nodes[2 * r]));
        const glm::vec3 hi =
            glm::max(glm::vec3(s.top_nodes[2 * l + 1]), glm::vec3(s.top_nodes[2 * r + 1]));
        s.top_nodes[2 * i] = glm::vec4(lo, s.top_nodes[2 * i].w);
        s.top_nodes[2 * i + 1] = glm::vec4(hi, s.top_nodes[2 * i + 1].w);
    }
    // glBufferSubData is ordered after the previous pass's reads by GL itself.
    constexpr GLsizeiptr kVec4 = sizeof(glm::vec4);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers.bvh_nodes);
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, GLsizeiptr(s.top_nodes.size()) * kVec4,
                    s.top_nodes.data());
    if (s.end_record > s.first_record) {
        const std::size_t first = kInstanceRecordVec4 * s.first_record;
        const std::size_t count = kInstanceRecordVec4 * (s.end_record - s.first_record);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers.instances);
        glBufferSubData(GL_SHADER_STORAGE_BUFFER, GLintptr(first) * kVec4,
                        GLsizeiptr(count) * kVec4, s.records.data() + first);
    }
    s.refit_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Each deforming mesh at time t: its packed triangles' corners (and normals) rewritten, its
// bottom tree refitted (leaves padded as the build pads them, inner boxes the unions of
// their children's; the topology built at the frame's time stays), and the three ranges
// uploaded. A triangle kept or dropped as degenerate at the frame stays so.
void Renderer::Gpu::deform_meshes(double t) {
    MotionScratch& s = motion;
    constexpr GLsizeiptr kVec4 = sizeof(glm::vec4);
    for (std::size_t k = 0; k < s.meshes.size(); ++k) {
        DeformScratch& d = s.meshes[k];
        if (d.children.empty()) continue;  // no instance traces it
        const DeformMotion& dm = scene.motion->meshes[k];
        dm.at(t, s.positions, s.normals);
        for (std::size_t i = 0; i < d.end_triangle - d.first_triangle; ++i) {
            glm::vec4* tri = &d.triangles[3 * i];
            const glm::uvec3 v = dm.triangles[static_cast<std::size_t>(float_bits(tri[1].w))];
            for (int c = 0; c < 3; ++c) tri[c] = glm::vec4(s.positions[v[c]], tri[c].w);
            if (s.normals.empty()) continue;  // the mesh has none (its zeros, or faces')
            for (int c = 0; c < 3; ++c)
                d.normals[3 * i + c] = glm::vec4(s.normals[v[c]], d.normals[3 * i + c].w);
        }
        for (std::size_t j = d.children.size(); j-- > 0;) {
            const glm::ivec2 c = d.children[j];
            Aabb box;
            if (c.x < 0) {
                const auto first = static_cast<std::size_t>(float_bits(d.nodes[2 * j].w));
                const auto count = static_cast<std::size_t>(float_bits(d.nodes[2 * j + 1].w));
                for (std::size_t i = first; i < first + count; ++i)
                    for (int v = 0; v < 3; ++v)
                        box.grow(glm::vec3(d.triangles[3 * (i - d.first_triangle) + v]));
                box = pad_box(box);
            } else {
                box = Aabb{glm::vec3(d.nodes[2 * c.x]), glm::vec3(d.nodes[2 * c.x + 1])};
                box.grow(Aabb{glm::vec3(d.nodes[2 * c.y]), glm::vec3(d.nodes[2 * c.y + 1])});
            }
            d.nodes[2 * j] = glm::vec4(box.lo, d.nodes[2 * j].w);
            d.nodes[2 * j + 1] = glm::vec4(box.hi, d.nodes[2 * j + 1].w);
        }
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers.bvh_nodes);
        glBufferSubData(GL_SHADER_STORAGE_BUFFER, GLintptr(2 * d.root) * kVec4,
                        GLsizeiptr(d.nodes.size()) * kVec4, d.nodes.data());
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers.triangles);
        glBufferSubData(GL_SHADER_STORAGE_BUFFER, GLintptr(3 * d.first_triangle) * kVec4,
                        GLsizeiptr(d.triangles.size()) * kVec4, d.triangles.data());
        if (s.normals.empty() || d.normals.empty()) continue;
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers.normals);
        glBufferSubData(GL_SHADER_STORAGE_BUFFER, GLintptr(3 * d.first_triangle) * kVec4,
                        GLsizeiptr(d.normals.size()) * kVec4, d.normals.data());
    }
}

}  // namespace glslppm
