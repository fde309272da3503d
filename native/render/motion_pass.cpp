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

// What deform_mesh.comp reads, for every deforming mesh at once: the steps' vertices and
// normals, each packed triangle's vertices, and the refit's entries per depth.
struct DeformTables {
    std::vector<glm::vec4> positions, normals;
    std::vector<glm::uvec4> triangles;              // (packed triangle, its three vertices)
    std::vector<std::vector<glm::ivec4>> by_depth;  // (node, left, right, 0); -1: a leaf's
};

// A deforming mesh's bottom tree (the nodes of one mesh lie in preorder, left child first,
// from its root) into the tables: its packed triangles' vertices and its nodes by depth.
DeformScratch start_deformation(const TwoLevelBvh& tree, std::uint32_t root,
                                std::uint32_t node_count, const DeformMotion& dm,
                                DeformTables& t) {
    DeformScratch d;
    d.traced = true;
    d.first_entry = static_cast<std::uint32_t>(t.triangles.size());
    std::vector<glm::ivec2> children(node_count, glm::ivec2(-1));
    std::vector<std::uint32_t> depth(node_count, 0);
    std::vector<std::uint32_t> open;  // inner nodes still waiting for their right child
    for (std::uint32_t j = 0; j < node_count; ++j) {
        if (j > 0) {
            // j is the left child of the node before it, if that one is inner; else the right
            // child of the innermost inner node still waiting for one.
            std::uint32_t parent = j - 1;
            if (float_bits(tree.nodes[2 * (root + parent) + 1].w) == 0) {
                children[parent].x = static_cast<std::int32_t>(j);
            } else {
                parent = open.back();
                open.pop_back();
                children[parent].y = static_cast<std::int32_t>(j);
            }
            depth[j] = depth[parent] + 1;
        }
        const std::int32_t count = float_bits(tree.nodes[2 * (root + j) + 1].w);
        if (count == 0) {
            open.push_back(j);
            continue;
        }
        const std::int32_t first = float_bits(tree.nodes[2 * (root + j)].w);
        for (std::int32_t i = first; i < first + count; ++i) {
            // Vertex 1's w: the triangle's index in the mesh.
            const auto id = static_cast<std::size_t>(float_bits(tree.triangles[3 * i + 1].w));
            const glm::uvec3 v = dm.triangles[id];
            t.triangles.emplace_back(static_cast<std::uint32_t>(i), v.x, v.y, v.z);
        }
    }
    d.entry_count = static_cast<std::uint32_t>(t.triangles.size()) - d.first_entry;
    for (std::uint32_t j = 0; j < node_count; ++j) {
        if (t.by_depth.size() <= depth[j]) t.by_depth.resize(depth[j] + 1);
        const glm::ivec2 c = children[j];
        const auto global = [&](std::int32_t local) {
            return local < 0 ? -1 : static_cast<std::int32_t>(root) + local;
        };
        t.by_depth[depth[j]].emplace_back(static_cast<std::int32_t>(root + j), global(c.x),
                                          global(c.y), 0);
    }
    d.first_vertex = static_cast<std::uint32_t>(t.positions.size());
    d.vertex_count = static_cast<std::uint32_t>(dm.positions[0].size());
    for (std::size_t step = 0; step < dm.positions.size(); ++step)
        for (std::uint32_t v = 0; v < d.vertex_count; ++v) {
            t.positions.emplace_back(dm.positions[step][v], 0.0f);
            t.normals.emplace_back(dm.normals.empty() ? glm::vec3(0.0f) : dm.normals[step][v],
                                   0.0f);
        }
    Aabb box;
    dm.box(box.lo, box.hi);
    box = pad_box(box);
    d.root_lo = box.lo;
    d.root_hi = box.hi;
    return d;
}

// The tables uploaded, the depths deepest first.
void upload_deformation(Renderer::Gpu& g, DeformTables& t) {
    MotionScratch& s = g.motion;
    std::vector<glm::ivec4> refit;
    for (std::size_t depth = t.by_depth.size(); depth-- > 0;) {
        s.refit_levels.push_back(static_cast<std::uint32_t>(refit.size()));
        refit.insert(refit.end(), t.by_depth[depth].begin(), t.by_depth[depth].end());
    }
    s.refit_levels.push_back(static_cast<std::uint32_t>(refit.size()));
    const auto bytes = [](const auto& v) { return v.size() * sizeof(v[0]); };
    const std::size_t largest = g.largest_block(false);
    if (largest > 0 && bytes(t.positions) > largest)
        throw gl::GlError("the deforming meshes' vertices at their motion steps need " +
                          std::to_string(bytes(t.positions) >> 20) +
                          " MiB, more than this GPU's largest storage buffer (" +
                          std::to_string(largest >> 20) +
                          " MiB): lower the objects' motion blur steps or their vertex count");
    g.make_buffer(BINDING_DEFORM_POSITIONS, bytes(t.positions), t.positions.data(),
                  "deforming meshes' steps");
    g.make_buffer(BINDING_DEFORM_NORMALS, bytes(t.normals), t.normals.data(),
                  "deforming meshes' normals");
    g.make_buffer(BINDING_DEFORM_TRIANGLES, bytes(t.triangles), t.triangles.data(),
                  "deforming meshes' triangles");
    g.make_buffer(BINDING_DEFORM_REFIT, bytes(refit), refit.data(), "deforming meshes' trees");
}

// The copies and the map from records to top leaves, once per worker.
void start_scratch(Renderer::Gpu& g, const TwoLevelBvh& tree, const MotionPlan& plan) {
    MotionScratch& s = g.motion;
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
    DeformTables tables;
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
            if (!s.meshes.back().traced)
                s.meshes.back() = start_deformation(
                    tree, static_cast<std::uint32_t>(float_bits(rec[6].x)),
                    static_cast<std::uint32_t>(float_bits(rec[6].y)), plan.meshes[k], tables);
        }
    }
    if (!plan.meshes.empty()) upload_deformation(g, tables);
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
    if (!plan.lights.empty()) {
        move_lights(t);
        move_area_lights(t);
    }
    if (!plan.mesh_emitters.empty()) move_mesh_emitters(t);
    if ((plan.instances.empty() && plan.meshes.empty()) || !two_level) return;
    const auto start = std::chrono::steady_clock::now();
    const TwoLevelBvh& tree = *two_level;
    MotionScratch& s = motion;
    if (s.top_nodes.empty()) start_scratch(*this, tree, plan);
    for (std::size_t k = 0; k < plan.instances.size(); ++k)
        write_instance_transform(&s.records[kInstanceRecordVec4 * (plan.instances[k] + 1u)],
                                 plan.instance_motion[k].at(t));
    // The moved and deformed instances' leaf boxes (instance_world_box: the mesh's root box
    // mapped and padded as the build maps it; a deforming mesh's box over all its steps).
    for (std::size_t record : s.refit_records) {
        const glm::vec4* rec = &s.records[kInstanceRecordVec4 * record];
        const std::int32_t leaf = s.leaf_of_instance[record];
        if (leaf < 0) continue;  // an empty mesh: never in the top tree
        const auto mesh = static_cast<std::size_t>(float_bits(rec[7].x)) - 1u;  // the scene's
        const std::int32_t deformed =
            mesh < s.deformed_of_mesh.size() ? s.deformed_of_mesh[mesh] : -1;
        const auto root = static_cast<std::size_t>(float_bits(rec[6].x));
        const DeformScratch* d = deformed >= 0 ? &s.meshes[std::size_t(deformed)] : nullptr;
        const Aabb box = instance_world_box(d ? d->root_lo : glm::vec3(tree.nodes[2 * root]),
                                            d ? d->root_hi : glm::vec3(tree.nodes[2 * root + 1]),
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
    deform_meshes(t);
    s.refit_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Each deforming mesh at time t, on the GPU (deform_mesh.comp): its packed triangles'
// corners and normals, then its bottom tree's boxes, one depth at a time from the deepest.
// A triangle kept or dropped as degenerate at the frame stays so; the topology stays.
void Renderer::Gpu::deform_meshes(double t) {
    const MotionScratch& s = motion;
    if (s.refit_levels.empty()) return;
    const gl::ComputeProgram& vertices = *programs.deform_vertices;
    vertices.use();
    for (std::size_t k = 0; k < s.meshes.size(); ++k) {
        const DeformScratch& d = s.meshes[k];
        if (!d.traced || d.entry_count == 0) continue;  // no instance traces it
        const DeformMotion& dm = scene.motion->meshes[k];
        std::size_t a = 0, b = 0;
        float u = 0.0f;
        dm.segment(t, a, b, u);
        glUniform1ui(vertices.uniform("u_first"), d.first_entry);
        glUniform1ui(vertices.uniform("u_count"), d.entry_count);
        glUniform1ui(vertices.uniform("u_step_a"),
                     d.first_vertex + static_cast<std::uint32_t>(a) * d.vertex_count);
        glUniform1ui(vertices.uniform("u_step_b"),
                     d.first_vertex + static_cast<std::uint32_t>(b) * d.vertex_count);
        glUniform1f(vertices.uniform("u_blend"), u);
        glUniform1ui(vertices.uniform("u_normals"), !dm.normals.empty() && buffers.normals);
        dispatch(vertices, d.entry_count);
    }
    const gl::ComputeProgram& refit = *programs.deform_refit;
    for (std::size_t level = 0; level + 1 < s.refit_levels.size(); ++level) {
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        const std::uint32_t first = s.refit_levels[level];
        const std::uint32_t count = s.refit_levels[level + 1] - first;
        refit.use();
        glUniform1ui(refit.uniform("u_first"), first);
        glUniform1ui(refit.uniform("u_count"), count);
        dispatch(refit, count);
    }
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

}  // namespace glslppm
