// The camera ray of shaders/common/camera.glsl on the CPU, from the Frame's camera fields
// (frame_camera in scene_preparation.h fills them): the automatic radius looks through it,
// and tests/native/camera_ray_probe_test.cpp holds the shader to it.
#pragma once

#include <glm/glm.hpp>

#include "bvh/intersect.h"
#include "render/gpu_layout.h"

namespace glslppm {

// pixel: the point in the image's pixels (x + jx, y + jy; row 0 at the top). lens_u: two
// numbers in [0, 1) for the point on the lens, used only with depth_of_field (the programs'
// HAS_DEPTH_OF_FIELD) by a perspective camera. The direction is not normalized; tmin and
// tmax are Ray's defaults.
Ray camera_ray_at(const FrameBlock& frame, glm::vec2 pixel, glm::vec2 lens_u,
                  bool depth_of_field);

// Uniform point on the unit disc by the concentric mapping (Shirley and Chiu 1997), as
// sample_disc in shaders/common/sampling.glsl.
glm::vec2 sample_disc(float u1, float u2);

}  // namespace glslppm
