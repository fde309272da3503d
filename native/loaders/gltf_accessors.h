// Reading glTF accessors with every offset, stride and count checked against the buffer
// they point into, so that a corrupt file is an error naming the accessor, never a read
// past the end.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "loaders/tinygltf_config.h"

namespace glslppm::gltf {

// Element `index` of accessor `accessor` as `components` floats each (the accessor's type
// must have that many). Integer components are converted as glTF prescribes (normalized:
// c / max, at least -1). Every value must be finite. `what` names the use in messages
// ("meshes[0].primitives[1].attributes.POSITION"). Throws SceneFileError via `fail`.
std::vector<float> read_floats(const tinygltf::Model& model, int accessor, int components,
                               const std::string& what, const std::string& file);

// An index accessor (unsigned byte, short or int scalars).
std::vector<std::uint32_t> read_indices(const tinygltf::Model& model, int accessor,
                                        const std::string& what, const std::string& file);

// The number of elements of accessor `accessor` (checked to be a valid index).
std::size_t accessor_count(const tinygltf::Model& model, int accessor, const std::string& what,
                           const std::string& file);

}  // namespace glslppm::gltf
