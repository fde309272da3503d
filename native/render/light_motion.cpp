// Moving lamps (docs/motion_blur.md): per pass, each moving point, spot or sun light's
// emitter record is rewritten at the pass's time and its range of the emitter table
// uploaded; light samples, photons (emit_photon) and the sphere lights that specular rays
// see (common/sphere_lights.glsl) all read the table, so they all see the light there.
// Scenes whose lights stand still never come here.
#include <algorithm>
#include <chrono>

#include "render/emitters.h"
#include "render/gpu_layout.h"
#include "render/pipeline.h"

namespace glslppm {

Light MovingLight::at(double t) const {
    const glm::mat4 m = motion.at(t);
    Light l = frame;
    l.position = glm::vec3(m[3]);
    l.direction = -glm::vec3(m[2]);  // Blender's lamps shine along their local -Z
    l.to_world = m;
    return l;
}

void Renderer::Gpu::move_lights(double t) {
    const auto start = std::chrono::steady_clock::now();
    const MotionPlan& plan = *scene.motion;
    const EmitterTable& table = scene.emitters;
    const auto record_of = [&](const MovingLight& l) {
        return l.light < table.light_records.size() ? table.light_records[l.light] : -1;
    };
    // The records' range that holds every moving light (a dark light has none).
    std::size_t first = table.count, end = 0;
    for (const MovingLight& l : plan.lights) {
        const std::int32_t r = record_of(l);
        if (r < 0) continue;
        first = std::min(first, std::size_t(r));
        end = std::max(end, std::size_t(r) + 1);
    }
    if (end <= first) return;
    // From the table as it is now (update_tables may have replaced its powers).
    std::vector<glm::vec4>& range = motion.light_records;
    range.assign(table.records.begin() + std::ptrdiff_t(EMITTER_VEC4 * first),
                 table.records.begin() + std::ptrdiff_t(EMITTER_VEC4 * end));
    for (const MovingLight& l : plan.lights) {
        const std::int32_t r = record_of(l);
        if (r >= 0) place_light(l.at(t), &range[EMITTER_VEC4 * (std::size_t(r) - first)]);
    }
    // glBufferSubData is ordered after the previous pass's reads by GL itself.
    constexpr GLsizeiptr kVec4 = sizeof(glm::vec4);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers.emitter_records);
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, GLintptr(EMITTER_VEC4 * first) * kVec4,
                    GLsizeiptr(range.size()) * kVec4, range.data());
    motion.refit_seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace glslppm
