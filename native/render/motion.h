// Motion blur by one shutter time per pass (docs/motion_blur.md): every pass renders the
// whole scene at one instant, its eye paths and photons alike, and the passes' mean is the
// blurred image. The instant is a function of (seed, pass index) only, so that PPPM's farm
// chunks and several devices render the passes one run would.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "scene/scene.h"

namespace glslppm {

// Where in the shutter pass `pass_index` looks, in [0, 1): the base-2 radical inverse of
// the index (van der Corput), rotated by an offset drawn from the seed (Cranley-Patterson),
// so that any 2^k consecutive passes from a multiple of 2^k take one time in each 2^-k of
// the shutter (the strata shifted by the offset, modulo 1).
double shutter_sample(std::uint64_t seed, std::uint64_t pass_index);

// A transform split as Cycles splits it (transform_motion_decompose): translation, the
// rotation of the polar decomposition A = R S as a unit quaternion, and the stretch S.
struct DecomposedTransform {
    glm::dvec3 translation{0.0};
    glm::dquat rotation{1.0, 0.0, 0.0, 0.0};
    glm::dmat3 stretch{1.0};
};
DecomposedTransform decompose_transform(const glm::mat4& m);
// Between two steps at u in [0, 1]: translation and stretch linearly, rotation by slerp
// along the shorter arc.
glm::mat4 interpolate_transform(const DecomposedTransform& a, const DecomposedTransform& b,
                                double u);

// Steps decomposed once; `at(t)` the transform at time t (held at the ends outside them).
struct TransformMotion {
    std::vector<double> times;
    std::vector<DecomposedTransform> steps;
    std::vector<glm::mat4> matrices;
    explicit TransformMotion(const TransformSteps& s);
    glm::mat4 at(double t) const;
};

// A deforming instance mesh's steps (MeshDeformation), with the mesh's triangles: `at(t)`
// gives every vertex's position (and normal, where the mesh has normals) at time t, linearly
// between the steps and held at the ends (render/deformation.cpp).
struct DeformMotion {
    std::uint32_t mesh = 0;
    std::vector<double> times;
    std::vector<std::vector<glm::vec3>> positions, normals;
    std::vector<glm::uvec3> triangles;
    // The two steps around time t and how far between them: deform_mesh.comp blends each
    // vertex a + u (b - a), its normal likewise and renormalized.
    void segment(double t, std::size_t& a, std::size_t& b, float& u) const;
    // The mesh's box over every step (a vertex between steps stays within their box).
    void box(glm::vec3& lo, glm::vec3& hi) const;
};

// Throws SceneError naming the problem: a shutter that is not finite or not > 0 while
// anything moves, a shutter curve of one point, a negative or non-finite value, or none
// above 0, step times not finite or not strictly increasing, matrices not finite,
// not affine, singular or changing handedness, an instance out of range or given twice,
// camera fov_x values not one per step or not in (0, pi); for deformation, a mesh out of
// range or given twice, a step whose vertex count is not the mesh's, a coordinate or normal
// not finite, normals missing where the mesh has them or given where it has none.
void validate_motion(const Scene& scene);
void validate_deformation(const Scene& scene);

// The shutter curve's inverse cumulative distribution (SceneMotion::shutter_curve): a
// stratified sample u of [0, 1) becomes a place in the shutter, [0, 1], drawn with density
// proportional to the piecewise-linear curve, so that the passes' strata stay strata of the
// curve's weight (Cycles' shutter table, solved exactly per segment instead of tabulated).
struct ShutterCurve {
    std::vector<double> values;  // normalized: the curve's area over [0, 1] is 1
    std::vector<double> cdf;     // the area up to each point: 0 first, 1 last
    explicit ShutterCurve(const std::vector<float>& curve);
    double position(double u) const;
};

// A moving point, spot or sun light: the scene's light (its other fields) and its steps.
// `at(t)`: the light at time t, its position the transform's origin and its direction the
// transform's -Z (render/light_motion.cpp).
struct MovingLight {
    std::uint32_t light = 0;  // index into Scene::lights
    Light frame;
    TransformMotion motion;
    // An area light's triangles in the geometry mesh (render/area_lights.h): [first, end).
    std::int64_t first_triangle = -1, end_triangle = -1;
    Light at(double t) const;
};

// A moving instance that emits light (render/emitter_motion.cpp). Photons and light samples
// start from world-space emitter triangles, so it is placed once with them, in the geometry
// mesh as triangles [first_triangle, end_triangle) (flatten_instances appends it), and each
// pass rewrites those triangles, their normals and their emitter records at its interpolated
// transform, as a moving area light's are. Its mesh's own-space triangles are kept for that.
// A transform whose scale changes in the shutter keeps the frame's power (as area lights do).
struct MovingMeshEmitter {
    std::uint32_t instance = 0;  // index into Scene::instances
    TransformMotion motion;
    std::vector<glm::vec3> positions, normals;  // the mesh's, in its own space (normals: or none)
    std::vector<glm::uvec3> triangles;          // corners as flattened (a mirror swaps two)
    std::int64_t first_triangle = -1, end_triangle = -1;
};

// What moves, once validated; null from plan_motion when nothing does (every step the same
// matrix), and then nothing of this runs.
struct MotionPlan {
    double shutter_open = 0.0, shutter_length = 0.0;
    std::vector<std::uint32_t> instances;  // the scene's indices of the moving instances
    std::vector<TransformMotion> instance_motion;
    std::vector<DeformMotion> meshes;  // the instance meshes that deform
    std::vector<MovingLight> lights;   // the lamps that move (their emitter records move)
    std::vector<MovingMeshEmitter> mesh_emitters;  // moving instances that emit, placed once
    std::unique_ptr<TransformMotion> camera;  // null: the camera stands still
    std::vector<double> camera_fov_x;         // empty: the camera's own
    Camera frame_camera;                      // the scene's camera (its other fields)
    std::shared_ptr<const ShutterCurve> shutter_curve;  // null: a box shutter
    double time(std::uint64_t seed, std::uint64_t pass_index) const {
        const double u = shutter_sample(seed, pass_index);
        return shutter_open + shutter_length * (shutter_curve ? shutter_curve->position(u) : u);
    }
    Camera camera_at(double t) const;
    // The same instances', meshes' and lights' motion under a camera that stands still; null
    // if nothing else moves.
    std::shared_ptr<const MotionPlan> with_still_camera() const;
    // The same motion with the instances that `emitting` marks taken out of the moving
    // instances (they are placed once, their triangles in the geometry mesh from
    // first_triangle[i]): those that move become mesh_emitters.
    std::shared_ptr<const MotionPlan> with_emitters_placed_once(
        const Scene& scene, const std::vector<bool>& emitting,
        const std::vector<std::int64_t>& first_triangle) const;
};
std::shared_ptr<const MotionPlan> plan_motion(const Scene& scene);

// Moving area lights (render/area_light_motion.cpp): where their triangles lie in the
// geometry mesh, and the placed-once tree's leaves that hold them, or a moving emitting
// instance's triangles (MotionPlan::mesh_emitters), and the nodes above, grown over their
// whole sweep, so that the tree holds them at every time.
struct PackedBvh;
void locate_area_lights(const Scene& scene, std::vector<MovingLight>& lights);
void grow_over_area_light_motion(const MotionPlan& plan, PackedBvh& bvh);

// Grows [lo, hi] over every place a moving instance's mesh takes in the shutter (sampled
// finely between the steps, padded by the chord error of a slerp) and every place a
// deforming mesh's vertices take, in each of its instances.
void grow_bounds_over_motion(const Scene& scene, const MotionPlan& plan, glm::vec3& lo,
                             glm::vec3& hi);
// The still instances of deforming meshes (render/deformation.cpp).
void grow_bounds_over_deformation(const Scene& scene, const MotionPlan& plan, glm::vec3& lo,
                                  glm::vec3& hi);

}  // namespace glslppm
