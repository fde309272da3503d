// Moving instances that emit light (docs/motion_blur.md). Photons and light samples start
// from world-space emitter triangles, so such an instance is placed once, in the geometry
// mesh (flatten_instances); the placed-once tree's leaves that hold it are grown over its
// sweep at preparation (grow_over_area_light_motion), and each pass rewrites its packed
// triangles, their normals and their emitter records at its interpolated transform, in
// runs of consecutive entries, one glBufferSubData a run. Scenes without one never come here.
#include <bit>

#include "render/emitters.h"
#include "render/gpu_layout.h"
#include "render/pipeline.h"

namespace glslppm {
namespace {

inline std::int32_t float_bits(float f) { return std::bit_cast<std::int32_t>(f); }

// Uploads `data` (`width` vec4s per entry, entries at `at[k]`) in runs of consecutive
// entries.
void upload_runs(GLuint buffer, const std::vector<std::size_t>& at,
                 const std::vector<glm::vec4>& data, std::size_t width) {
    constexpr GLsizeiptr kVec4 = sizeof(glm::vec4);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffer);
    for (std::size_t k = 0; k < at.size();) {
        std::size_t end = k + 1;
        while (end < at.size() && at[end] == at[end - 1] + 1) ++end;
        glBufferSubData(GL_SHADER_STORAGE_BUFFER, GLintptr(width * at[k]) * kVec4,
                        GLsizeiptr(width * (end - k)) * kVec4, &data[width * k]);
        k = end;
    }
}

}  // namespace

void Renderer::Gpu::move_mesh_emitters(double t) {
    const MotionPlan& plan = *scene.motion;
    const EmitterTable& table = scene.emitters;
    const std::vector<glm::vec4>& triangles = two_level ? two_level->triangles : bvh->triangles;
    const std::vector<glm::vec4>& normals = two_level ? two_level->normals : bvh->normals;
    MotionScratch& s = motion;
    if (!s.mesh_emitters_traced) {
        // Mesh 0's packed triangles come first in two levels.
        s.mesh_emitters_traced = true;
        for (std::size_t i = 0; i < table.triangle_records.size(); ++i) {
            const std::int64_t id = float_bits(triangles[3 * i + 1].w);
            for (std::size_t k = 0; k < plan.mesh_emitters.size(); ++k) {
                const MovingMeshEmitter& e = plan.mesh_emitters[k];
                if (id >= e.first_triangle && id < e.end_triangle)
                    s.emitter_triangles.push_back(
                        {k, i, std::size_t(id - e.first_triangle), table.triangle_records[i]});
            }
        }
    }
    const bool with_normals = buffers.normals && !normals.empty();
    std::vector<glm::mat4> to_world(plan.mesh_emitters.size());
    std::vector<glm::mat3> normal_matrix(plan.mesh_emitters.size());
    for (std::size_t k = 0; k < to_world.size(); ++k) {
        to_world[k] = plan.mesh_emitters[k].motion.at(t);
        normal_matrix[k] =
            glm::transpose(glm::mat3(glm::inverse(glm::dmat3(glm::mat3(to_world[k])))));
    }
    std::vector<std::size_t> packed, records;
    std::vector<glm::vec4> corners, corner_normals, record_corners;
    for (const EmitterTriangle& a : s.emitter_triangles) {
        const MovingMeshEmitter& e = plan.mesh_emitters[a.emitter];
        const glm::uvec3 tri = e.triangles[a.local];
        glm::vec3 v[3];
        for (int c = 0; c < 3; ++c) {
            // As flatten_instances places it (to_world x, the normal by A^-T, not normalized).
            v[c] = glm::vec3(to_world[a.emitter] * glm::vec4(e.positions[tri[c]], 1.0f));
            corners.emplace_back(v[c], triangles[3 * a.packed + c].w);
            if (!with_normals) continue;
            const glm::vec4 kept = normals[3 * a.packed + c];
            const glm::mat3& n = normal_matrix[a.emitter];
            corner_normals.push_back(e.normals.empty() ? kept
                                                       : glm::vec4(n * e.normals[tri[c]], kept.w));
        }
        packed.push_back(a.packed);
        if (a.record < 0) continue;  // dark
        const std::size_t at = EMITTER_VEC4 * std::size_t(a.record);
        for (int c = 0; c < 3; ++c)
            record_corners.emplace_back(v[c], table.records[at + std::size_t(c)].w);
        record_corners.push_back(table.records[at + 3]);
        records.push_back(std::size_t(a.record));
    }
    upload_runs(buffers.triangles, packed, corners, 3);
    if (with_normals) upload_runs(buffers.normals, packed, corner_normals, 3);
    upload_runs(buffers.emitter_records, records, record_corners, EMITTER_VEC4);
}

}  // namespace glslppm
