// glTF cameras and KHR_lights_punctual lights, placed by the node that refers to them, in
// the units and conventions of Scene (Blender's).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "loaders/tinygltf_config.h"
#include "scene/scene.h"

namespace glslppm::gltf {

// The camera at the node's frame (scale removed). Perspective: fov_x from yfov and the
// render's aspect (width / height); orthographic: ortho_scale = 2 max(xmag, ymag aspect).
// `element` names the camera ("cameras[0]") in errors (SceneFileError).
Camera convert_camera(const tinygltf::Camera& camera, const glm::mat4& to_world, float aspect,
                      const std::string& file, const std::string& element);

// Blender's glTF importer's conversion ("Standard" lighting mode, 683 lm/W): point and spot
// lights W = cd * 4 pi / 683, spot_size = 2 outer, spot_blend = 1 - inner / outer; a
// directional light becomes a sun of lux / 683 W/m^2. Lights shine down the node's -Z.
// An unknown type is skipped (nullopt) with a warning. glTF has no light size; the light's
// extras may carry Blender's: "radius" (metres, point and spot: a sphere light, lit as
// Cycles lights it with "soft_falloff", a bool, true where absent) and "angle" (radians, a
// sun's angular diameter), as scripts/showcase_gltf.py writes them.
std::optional<Light> convert_light(const tinygltf::Light& light, const glm::mat4& to_world,
                                   const std::string& file, const std::string& element,
                                   std::vector<std::string>& warnings);

}  // namespace glslppm::gltf
