// Deformation motion blur (docs/motion_blur.md): an instance mesh's vertices at Blender's
// motion steps, placed per pass at the pass's time. Here: the steps' validation, the
// interpolation and the boxes the scene's bounds must hold; the per-pass refit of the mesh's
// bottom tree is in motion_pass.cpp.
#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>

#include "render/motion.h"
#include "scene/scene_validation.h"

namespace glslppm {
namespace {

bool finite(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

void check_arrays(const std::vector<std::vector<glm::vec3>>& steps, std::size_t vertices,
                  const std::string& name, const char* what) {
    for (std::size_t k = 0; k < steps.size(); ++k) {
        const std::string step = name + " step " + std::to_string(k);
        if (steps[k].size() != vertices)
            throw SceneError(step + ": " + std::to_string(steps[k].size()) + " " + what +
                             " for the mesh's " + std::to_string(vertices) + " vertices");
        for (const glm::vec3& v : steps[k])
            if (!finite(v)) throw SceneError(step + ": a vertex's " + what + " is not finite");
    }
}

}  // namespace

void validate_deformation(const Scene& scene) {
    std::set<std::uint32_t> seen;
    for (std::size_t k = 0; k < scene.motion.meshes.size(); ++k) {
        const MeshDeformation& d = scene.motion.meshes[k];
        const std::string name = "motion.meshes[" + std::to_string(k) + "]";
        if (d.mesh >= scene.instance_meshes.size())
            throw SceneError(name + ".mesh: " + std::to_string(d.mesh) + " is out of range (" +
                             std::to_string(scene.instance_meshes.size()) + " instance meshes)");
        if (!seen.insert(d.mesh).second)
            throw SceneError(name + ".mesh: mesh " + std::to_string(d.mesh) +
                             " is given deformation twice");
        if (d.times.empty()) throw SceneError(name + ": no steps");
        if (d.positions.size() != d.times.size())
            throw SceneError(name + ": " + std::to_string(d.times.size()) + " times for " +
                             std::to_string(d.positions.size()) + " position arrays");
        for (std::size_t s = 0; s < d.times.size(); ++s)
            if (!std::isfinite(d.times[s]) || (s > 0 && !(d.times[s] > d.times[s - 1])))
                throw SceneError(name + " step " + std::to_string(s) +
                                 ": times are not finite and increasing");
        const MeshView& mesh = scene.instance_meshes[d.mesh];
        check_arrays(d.positions, mesh.positions.size(), name, "positions");
        if (mesh.normals.empty() && !d.normals.empty())
            throw SceneError(name + ": normals given for a mesh that has none");
        if (!mesh.normals.empty() && d.normals.size() != d.times.size())
            throw SceneError(name + ": the mesh has normals: give one normal array per step (" +
                             std::to_string(d.normals.size()) + " for " +
                             std::to_string(d.times.size()) + " steps)");
        check_arrays(d.normals, mesh.positions.size(), name, "normals");
    }
}

void DeformMotion::segment(double t, std::size_t& a, std::size_t& b, float& u) const {
    const std::size_t k = std::clamp<std::size_t>(
        std::upper_bound(times.begin(), times.end(), t) - times.begin(), 1,
        std::max<std::size_t>(times.size(), 2) - 1);
    a = times.size() == 1 ? 0 : k - 1;
    b = times.size() == 1 ? 0 : k;
    u = a == b ? 0.0f
               : static_cast<float>(std::clamp((t - times[a]) / (times[b] - times[a]), 0.0, 1.0));
}

void DeformMotion::box(glm::vec3& lo, glm::vec3& hi) const {
    for (const auto& step : positions)
        for (const glm::vec3& p : step) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
}

void grow_bounds_over_deformation(const Scene& scene, const MotionPlan& plan, glm::vec3& lo,
                                  glm::vec3& hi) {
    const std::set<std::uint32_t> moving(plan.instances.begin(), plan.instances.end());
    for (const DeformMotion& d : plan.meshes) {
        glm::vec3 a(std::numeric_limits<float>::infinity()), b(-a);
        d.box(a, b);
        for (std::uint32_t i = 0; i < scene.instances.size(); ++i) {
            const Instance& inst = scene.instances[i];
            if (inst.mesh != d.mesh || moving.count(i)) continue;  // moving: sampled there
            for (int c = 0; c < 8; ++c) {
                const glm::vec3 p((c & 1) ? b.x : a.x, (c & 2) ? b.y : a.y, (c & 4) ? b.z : a.z);
                const glm::vec3 w(inst.to_world * glm::vec4(p, 1.0f));
                const glm::vec3 pad(1e-5f * (glm::abs(w) + 1.0f));
                lo = glm::min(lo, w - pad);
                hi = glm::max(hi, w + pad);
            }
        }
    }
}

}  // namespace glslppm
