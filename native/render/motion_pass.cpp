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

// The copies and the map from records to top leaves, once per worker.
void start_scratch(MotionScratch& s, const TwoLevelBvh& tree, const MotionPlan& plan) {
    s.top_nodes.assign(tree.nodes.begin(), tree.nodes.begin() + 2 * tree.top_node_count);
    s.records = tree.instances;
    s.leaf_of_instance.assign(tree.instances.size() / kInstanceRecordVec4, -1);
    for (std::uint32_t i = 0; i < tree.top_node_count; ++i)
        if (tree.top_children[i].x < 0)
            s.leaf_of_instance[static_cast<std::size_t>(float_bits(tree.nodes[2 * i].w))] =
                static_cast<std::int32_t>(i);
    s.first_record = s.records.size();
    s.end_record = 0;
    for (std::uint32_t instance : plan.instances) {
        const std::size_t record = instance + 1u;  // record 0: the placed-once triangles
        s.first_record = std::min(s.first_record, record);
        s.end_record = std::max(s.end_record, record + 1);
    }
}

}  // namespace

void Renderer::Gpu::move_to_shutter_time(std::uint64_t pass_index) {
    const MotionPlan& plan = *scene.motion;
    const double t = plan.time(settings.seed, pass_index);
    if (plan.camera) camera_frame(plan.camera_at(t), settings, scene.frame);
    if (plan.instances.empty() || !two_level) return;
    const auto start = std::chrono::steady_clock::now();
    const TwoLevelBvh& tree = *two_level;
    MotionScratch& s = motion;
    if (s.top_nodes.empty()) start_scratch(s, tree, plan);
    // The moved instances' records and leaf boxes (instance_world_box: the mesh's root box
    // mapped and padded as the build maps it).
    for (std::size_t k = 0; k < plan.instances.size(); ++k) {
        const std::size_t record = plan.instances[k] + 1u;
        glm::vec4* rec = &s.records[kInstanceRecordVec4 * record];
        const glm::mat4 to_world = plan.instance_motion[k].at(t);
        write_instance_transform(rec, to_world);
        const std::int32_t leaf = s.leaf_of_instance[record];
        if (leaf < 0) continue;  // an empty mesh: never in the top tree
        const auto root = static_cast<std::size_t>(float_bits(rec[6].x));
        const Aabb box = instance_world_box(glm::vec3(tree.nodes[2 * root]),
                                            glm::vec3(tree.nodes[2 * root + 1]), to_world);
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
    const std::size_t first = kInstanceRecordVec4 * s.first_record;
    const std::size_t count = kInstanceRecordVec4 * (s.end_record - s.first_record);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers.instances);
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, GLintptr(first) * kVec4, GLsizeiptr(count) * kVec4,
                    s.records.data() + first);
    s.refit_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace glslppm
