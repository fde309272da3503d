// Motion blur's input (docs/motion_blur.md): the shutter and the transforms that move in it.
// Times are in frames relative to the frame rendered (Blender's subframes: -0.25 is a
// quarter frame before it). Empty (no steps anywhere): nothing moves and the scene renders
// exactly as without motion.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace glslppm {

// A transform at several times (Blender's motion steps), the times strictly increasing.
struct TransformSteps {
    std::vector<float> times;
    std::vector<glm::mat4> to_world;
};

// One instance's steps (Instance::to_world stays the frame's transform; an instance whose
// steps are all one matrix does not move and renders at Instance::to_world).
struct InstanceMotion {
    std::uint32_t instance = 0;  // index into Scene::instances
    TransformSteps steps;
};

// One light's steps (Light::position, direction and to_world stay the frame's): a point or
// spot light sits at each step's origin, a spot or sun light shines along its -Z, as
// Blender's lamps do. Area lights do not move yet (validate_motion says so).
struct LightMotion {
    std::uint32_t light = 0;  // index into Scene::lights
    TransformSteps steps;
};

// One instance mesh's vertex positions at several times (Blender's deformation motion:
// armatures, shape keys, modifiers), the times strictly increasing; each step holds every
// vertex of Scene::instance_meshes[mesh], in its order and in the mesh's own space. normals:
// one array per step where the mesh has normals, else empty. Between steps linearly.
struct MeshDeformation {
    std::uint32_t mesh = 0;  // index into Scene::instance_meshes
    std::vector<float> times;
    std::vector<std::vector<glm::vec3>> positions, normals;
};

struct SceneMotion {
    // The shutter: open at shutter_open, for shutter_length frames (> 0 where anything moves).
    float shutter_open = 0.0f;
    float shutter_length = 0.0f;
    // Blender's shutter curve: how far open the shutter is at evenly spaced points from its
    // opening (first) to its closing (last), linear between them; a pass's time is drawn in
    // proportion to it. Empty: a box (the shutter opens and closes at once).
    std::vector<float> shutter_curve;
    std::vector<InstanceMotion> instances;
    // The camera's transform and (if not empty, one per step) its fov_x at the steps.
    TransformSteps camera;
    std::vector<float> camera_fov_x;
    std::vector<MeshDeformation> meshes;
    std::vector<LightMotion> lights;

    bool empty() const {
        return instances.empty() && camera.times.empty() && meshes.empty() && lights.empty();
    }
};

}  // namespace glslppm
