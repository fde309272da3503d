#include "render/motion.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <set>

#include "scene/scene_validation.h"

namespace glslppm {
namespace {

std::uint64_t splitmix(std::uint64_t z) {
    z += 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

std::uint64_t reverse_bits(std::uint64_t v) {
    std::uint64_t r = 0;
    for (int k = 0; k < 64; ++k, v >>= 1) r = (r << 1) | (v & 1u);
    return r;
}

std::string number(double v) {
    char s[32];
    std::snprintf(s, sizeof s, "%g", v);
    return s;
}

void check_steps(const TransformSteps& s, const std::string& name) {
    if (s.times.empty()) throw SceneError(name + ": no steps");
    if (s.times.size() != s.to_world.size())
        throw SceneError(name + ": " + std::to_string(s.times.size()) + " times for " +
                         std::to_string(s.to_world.size()) + " matrices");
    double sign = 0.0;
    for (std::size_t k = 0; k < s.times.size(); ++k) {
        const std::string step = name + " step " + std::to_string(k);
        if (!std::isfinite(s.times[k])) throw SceneError(step + ": time is not finite");
        if (k > 0 && !(s.times[k] > s.times[k - 1]))
            throw SceneError(step + ": times are not increasing (" + number(s.times[k - 1]) +
                             " then " + number(s.times[k]) + ")");
        const glm::mat4& m = s.to_world[k];
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r)
                if (!std::isfinite(m[c][r])) throw SceneError(step + ": matrix is not finite");
        if (m[0][3] != 0.0f || m[1][3] != 0.0f || m[2][3] != 0.0f || m[3][3] != 1.0f)
            throw SceneError(step + ": matrix is not affine (the bottom row must be 0 0 0 1)");
        const double det = glm::determinant(glm::dmat3(glm::mat3(m)));
        if (!(std::abs(det) > 0.0) || !std::isfinite(1.0 / det))
            throw SceneError(step + ": matrix is singular (determinant " + number(det) + ")");
        if (sign != 0.0 && (det > 0.0) != (sign > 0.0))
            throw SceneError(step + ": matrix mirrors where the step before does not (the "
                             "interpolation would pass through a singular matrix)");
        sign = det;
    }
}

// The moving instances' or lights' entries (`kind` "instance" or "light", `member` their
// index field): each index within the scene's `count`, given once, its steps valid.
template <typename Moving>
void check_moving(const std::vector<Moving>& moving, std::uint32_t Moving::*member,
                  std::size_t count, const std::string& kind) {
    std::set<std::uint32_t> seen;
    for (std::size_t k = 0; k < moving.size(); ++k) {
        const std::string name = "motion." + kind + "s[" + std::to_string(k) + "]";
        const std::uint32_t i = moving[k].*member;
        if (i >= count)
            throw SceneError(name + "." + kind + ": " + std::to_string(i) +
                             " is out of range (" + std::to_string(count) + " " + kind + "s)");
        if (!seen.insert(i).second)
            throw SceneError(name + "." + kind + ": " + kind + " " + std::to_string(i) +
                             " is given motion twice");
        check_steps(moving[k].steps, name);
    }
}

bool moves(const TransformSteps& s) {
    return std::any_of(s.to_world.begin(), s.to_world.end(),
                       [&](const glm::mat4& m) { return m != s.to_world[0]; });
}

}  // namespace

double shutter_sample(std::uint64_t seed, std::uint64_t pass_index) {
    const double scale = std::ldexp(1.0, -53);
    const double u = static_cast<double>(reverse_bits(pass_index) >> 11) * scale;
    const double offset = static_cast<double>(splitmix(seed ^ 0x6d6f74696f6eull) >> 11) * scale;
    const double v = u + offset;
    return v >= 1.0 ? v - 1.0 : v;  // both are multiples of 2^-53: exact
}

DecomposedTransform decompose_transform(const glm::mat4& m) {
    DecomposedTransform d;
    d.translation = glm::dvec3(m[3]);
    const glm::dmat3 a{glm::mat3(m)};
    // Polar decomposition by Newton's iteration R <- (R + R^-T) / 2 (Higham 1986), as
    // Cycles' transform_motion_decompose does.
    glm::dmat3 r = a;
    for (int i = 0; i < 64; ++i) {
        const glm::dmat3 next = 0.5 * (r + glm::inverse(glm::transpose(r)));
        double change = 0.0;
        for (int c = 0; c < 3; ++c) change = std::max(change, glm::length(next[c] - r[c]));
        r = next;
        if (change < 1e-15) break;
    }
    if (glm::determinant(r) < 0.0) r = -r;  // a mirror stays in the stretch
    d.rotation = glm::normalize(glm::quat_cast(r));
    d.stretch = glm::transpose(glm::mat3_cast(d.rotation)) * a;
    return d;
}

glm::mat4 interpolate_transform(const DecomposedTransform& a, const DecomposedTransform& b,
                                double u) {
    glm::dquat qb = b.rotation;
    if (glm::dot(a.rotation, qb) < 0.0) qb = -qb;  // the shorter arc
    const glm::dquat q = glm::normalize(glm::slerp(a.rotation, qb, u));
    const glm::dmat3 s = a.stretch * (1.0 - u) + b.stretch * u;
    const glm::dmat3 m = glm::mat3_cast(q) * s;
    glm::mat4 out{glm::mat3(m)};
    out[3] = glm::vec4(glm::vec3(a.translation * (1.0 - u) + b.translation * u), 1.0f);
    return out;
}

TransformMotion::TransformMotion(const TransformSteps& s)
    : times(s.times.begin(), s.times.end()), matrices(s.to_world) {
    for (const glm::mat4& m : s.to_world) steps.push_back(decompose_transform(m));
}

ShutterCurve::ShutterCurve(const std::vector<float>& curve)
    : values(curve.begin(), curve.end()), cdf(curve.size(), 0.0) {
    const double h = 1.0 / static_cast<double>(values.size() - 1);
    for (std::size_t i = 1; i < values.size(); ++i)
        cdf[i] = cdf[i - 1] + 0.5 * h * (values[i - 1] + values[i]);
    const double area = cdf.back();
    for (std::size_t i = 0; i < values.size(); ++i) {
        values[i] /= area;
        cdf[i] /= area;
    }
    cdf.back() = 1.0;
}

double ShutterCurve::position(double u) const {
    // The segment [x_i, x_i + h] holding u (never one of no area: its cdf does not rise),
    // then s in [0, 1] with h (a s + (b - a) s^2 / 2) = u - cdf_i, in the form that stays
    // exact where a = 0 or b = a.
    const std::size_t i = std::clamp<std::size_t>(
        std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin(), 1, cdf.size() - 1) - 1;
    const double h = 1.0 / static_cast<double>(values.size() - 1);
    const double r = (u - cdf[i]) / h, a = values[i], b = values[i + 1];
    if (!(r > 0.0)) return static_cast<double>(i) * h;
    const double s = 2.0 * r / (a + std::sqrt(std::max(0.0, a * a + 2.0 * (b - a) * r)));
    return (static_cast<double>(i) + std::clamp(s, 0.0, 1.0)) * h;
}

glm::mat4 TransformMotion::at(double t) const {
    if (steps.size() == 1) return matrices[0];
    const std::size_t k = std::clamp<std::size_t>(
        std::upper_bound(times.begin(), times.end(), t) - times.begin(), 1, times.size() - 1);
    const double u = std::clamp((t - times[k - 1]) / (times[k] - times[k - 1]), 0.0, 1.0);
    return interpolate_transform(steps[k - 1], steps[k], u);
}

void validate_motion(const Scene& scene) {
    const SceneMotion& m = scene.motion;
    if (m.empty()) return;
    if (!std::isfinite(m.shutter_open))
        throw SceneError("motion.shutter_open is not finite");
    if (!(std::isfinite(m.shutter_length) && m.shutter_length > 0.0f))
        throw SceneError("motion.shutter_length is " + number(m.shutter_length) +
                         ": the shutter must stay open > 0 frames where anything moves");
    if (!m.shutter_curve.empty()) {
        if (m.shutter_curve.size() < 2)
            throw SceneError("motion.shutter_curve: one point; give none (a box shutter) or "
                             "at least two, from the opening to the closing");
        for (float v : m.shutter_curve)
            if (!(std::isfinite(v) && v >= 0.0f))
                throw SceneError("motion.shutter_curve: " + number(v) +
                                 " is not a shutter's openness (finite and >= 0)");
        if (*std::max_element(m.shutter_curve.begin(), m.shutter_curve.end()) <= 0.0f)
            throw SceneError("motion.shutter_curve is 0 everywhere: the shutter never opens");
    }
    check_moving(m.instances, &InstanceMotion::instance, scene.instances.size(), "instance");
    if (!m.camera.times.empty()) check_steps(m.camera, "motion.camera");
    if (!m.camera_fov_x.empty()) {
        if (m.camera_fov_x.size() != m.camera.times.size())
            throw SceneError("motion.camera_fov_x: " + std::to_string(m.camera_fov_x.size()) +
                             " values for " + std::to_string(m.camera.times.size()) +
                             " camera steps");
        for (float fov : m.camera_fov_x)
            if (!(std::isfinite(fov) && fov > 0.0f && fov < 3.14159265f))
                throw SceneError("motion.camera_fov_x: " + number(fov) +
                                 " is not an angle of view in (0, pi)");
    }
    check_moving(m.lights, &LightMotion::light, scene.lights.size(), "light");
    validate_deformation(scene);
}

Camera MotionPlan::camera_at(double t) const {
    Camera c = frame_camera;
    if (camera) c.to_world = camera->at(t);
    if (!camera_fov_x.empty()) {
        const std::vector<double>& times = camera->times;
        const std::size_t k = std::clamp<std::size_t>(
            std::upper_bound(times.begin(), times.end(), t) - times.begin(), 1, times.size() - 1);
        const double u = times.size() == 1 ? 0.0 : std::clamp(
            (t - times[k - 1]) / (times[k] - times[k - 1]), 0.0, 1.0);
        const double lo = camera_fov_x[times.size() == 1 ? 0 : k - 1];
        const double hi = camera_fov_x[times.size() == 1 ? 0 : k];
        c.fov_x = static_cast<float>(lo * (1.0 - u) + hi * u);
    }
    return c;
}

std::shared_ptr<const MotionPlan> MotionPlan::with_still_camera() const {
    if (instances.empty() && meshes.empty() && lights.empty() && mesh_emitters.empty())
        return nullptr;
    auto plan = std::make_shared<MotionPlan>();
    plan->shutter_open = shutter_open;
    plan->shutter_length = shutter_length;
    plan->shutter_curve = shutter_curve;
    plan->instances = instances;
    plan->instance_motion = instance_motion;
    plan->meshes = meshes;
    plan->lights = lights;
    plan->mesh_emitters = mesh_emitters;
    plan->frame_camera = frame_camera;
    return plan;
}

std::shared_ptr<const MotionPlan> MotionPlan::with_emitters_placed_once(
    const Scene& scene, const std::vector<bool>& emitting,
    const std::vector<std::int64_t>& first_triangle) const {
    auto plan = std::make_shared<MotionPlan>();
    plan->shutter_open = shutter_open;
    plan->shutter_length = shutter_length;
    plan->shutter_curve = shutter_curve;
    plan->meshes = meshes;
    plan->lights = lights;
    plan->mesh_emitters = mesh_emitters;
    if (camera) plan->camera = std::make_unique<TransformMotion>(*camera);
    plan->camera_fov_x = camera_fov_x;
    plan->frame_camera = frame_camera;
    for (std::size_t k = 0; k < instances.size(); ++k) {
        const std::uint32_t i = instances[k];
        if (!emitting[i]) {
            plan->instances.push_back(i);
            plan->instance_motion.push_back(instance_motion[k]);
            continue;
        }
        const Instance& inst = scene.instances[i];
        const MeshView& mesh = scene.instance_meshes[inst.mesh];
        MovingMeshEmitter e{i, instance_motion[k], {}, {}, {}, first_triangle[i], -1};
        e.positions.assign(mesh.positions.begin(), mesh.positions.end());
        e.normals.assign(mesh.normals.begin(), mesh.normals.end());
        const bool mirrored = glm::determinant(glm::mat3(inst.to_world)) < 0.0f;
        for (const glm::uvec3& t : mesh.triangles)
            e.triangles.push_back(mirrored ? glm::uvec3(t.x, t.z, t.y) : t);
        e.end_triangle = e.first_triangle + std::int64_t(e.triangles.size());
        plan->mesh_emitters.push_back(std::move(e));
    }
    return plan;
}

std::shared_ptr<const MotionPlan> plan_motion(const Scene& scene) {
    validate_motion(scene);
    const SceneMotion& m = scene.motion;
    auto plan = std::make_shared<MotionPlan>();
    plan->shutter_open = m.shutter_open;
    plan->shutter_length = m.shutter_length;
    if (!m.shutter_curve.empty())
        plan->shutter_curve = std::make_shared<const ShutterCurve>(m.shutter_curve);
    plan->frame_camera = scene.camera;
    for (const InstanceMotion& i : m.instances) {
        if (!moves(i.steps)) continue;
        plan->instances.push_back(i.instance);
        plan->instance_motion.emplace_back(i.steps);
    }
    for (const MeshDeformation& d : m.meshes) {
        const auto& p = d.positions;
        if (std::all_of(p.begin(), p.end(), [&](const auto& s) { return s == p[0]; }) &&
            std::all_of(d.normals.begin(), d.normals.end(),
                        [&](const auto& s) { return s == d.normals[0]; }))
            continue;  // every step the same: it does not deform
        DeformMotion dm{d.mesh, std::vector<double>(d.times.begin(), d.times.end()), d.positions,
                        d.normals, {}};
        const MeshView& mesh = scene.instance_meshes[d.mesh];
        dm.triangles.assign(mesh.triangles.begin(), mesh.triangles.end());
        plan->meshes.push_back(std::move(dm));
    }
    const bool zoom = !m.camera_fov_x.empty() &&
                      std::any_of(m.camera_fov_x.begin(), m.camera_fov_x.end(),
                                  [&](float f) { return f != m.camera_fov_x[0]; });
    if (!m.camera.times.empty() && (moves(m.camera) || zoom)) {
        plan->camera = std::make_unique<TransformMotion>(m.camera);
        if (zoom) plan->camera_fov_x.assign(m.camera_fov_x.begin(), m.camera_fov_x.end());
        for (std::size_t k = 0; k < m.camera.times.size(); ++k) {
            Camera c = scene.camera;
            c.to_world = m.camera.to_world[k];
            if (zoom) c.fov_x = m.camera_fov_x[k];
            validate_camera(c);
        }
    }
    for (const LightMotion& l : m.lights)
        if (moves(l.steps))
            plan->lights.push_back(
                MovingLight{l.light, scene.lights[l.light], TransformMotion(l.steps)});
    locate_area_lights(scene, plan->lights);
    if (plan->instances.empty() && plan->meshes.empty() && !plan->camera && plan->lights.empty())
        return nullptr;
    return plan;
}

void grow_bounds_over_motion(const Scene& scene, const MotionPlan& plan, glm::vec3& lo,
                             glm::vec3& hi) {
    constexpr int kSamples = 64;  // per step interval
    for (std::size_t k = 0; k < plan.instances.size(); ++k) {
        const std::uint32_t mesh_index = scene.instances[plan.instances[k]].mesh;
        const MeshView& mesh = scene.instance_meshes[mesh_index];
        if (mesh.positions.empty()) continue;
        glm::vec3 a(std::numeric_limits<float>::infinity()), b(-a);
        for (const glm::vec3& p : mesh.positions) {
            a = glm::min(a, p);
            b = glm::max(b, p);
        }
        for (const DeformMotion& d : plan.meshes)
            if (d.mesh == mesh_index) d.box(a, b);
        const TransformMotion& motion = plan.instance_motion[k];
        const std::size_t intervals = std::max<std::size_t>(motion.times.size() - 1, 1);
        for (std::size_t s = 0; s < intervals; ++s)
            for (int j = 0; j <= kSamples; ++j) {
                const double u = double(j) / kSamples;
                const double t = motion.times.size() == 1
                                     ? motion.times[0]
                                     : motion.times[s] * (1.0 - u) + motion.times[s + 1] * u;
                const glm::mat4 m = motion.at(t);
                glm::vec3 wlo(std::numeric_limits<float>::infinity()), whi(-wlo);
                for (int c = 0; c < 8; ++c) {
                    const glm::vec3 p((c & 1) ? b.x : a.x, (c & 2) ? b.y : a.y,
                                      (c & 4) ? b.z : a.z);
                    const glm::vec3 w(m * glm::vec4(p, 1.0f));
                    wlo = glm::min(wlo, w);
                    whi = glm::max(whi, w);
                }
                // A slerp between two samples strays from their chord by at most about
                // (angle / 2)^2 / 2 of the radius; 1e-3 of the box covers 64 samples of a
                // half turn.
                const glm::vec3 pad(1e-3f * glm::length(whi - wlo));
                lo = glm::min(lo, wlo - pad);
                hi = glm::max(hi, whi + pad);
            }
    }
    grow_bounds_over_deformation(scene, plan, lo, hi);
}

}  // namespace glslppm
