// glTF 2.0 (.gltf and .glb) into a Scene: triangle meshes under the node hierarchy, the
// first camera of the node tree, pbrMetallicRoughness materials with the transmission, ior
// and emissive-strength extensions, base-colour textures, and KHR_lights_punctual lights.
// The scene stays in glTF's Y-up frame.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "loaders/scene_file.h"

namespace glslppm {

LoadedScene load_gltf_file(const std::string& path, float aspect);

// Parses a .gltf (`binary` false) or .glb from memory. `name` appears in messages. External
// buffers and images are read relative to `base_dir`; with an empty base_dir nothing is read
// from disk (the fuzz target's mode), and external references are errors or warnings.
LoadedScene load_gltf_from_memory(std::span<const std::uint8_t> bytes, const std::string& name,
                                  float aspect, bool binary, const std::string& base_dir = "");

}  // namespace glslppm
