// glTF materials onto the material model (DESIGN.md): pbrMetallicRoughness with its
// textures, KHR_materials_transmission, _ior, _specular, _clearcoat and alpha modes as
// trees of Mix materials (gltf_materials.cpp, Converter::material, says how); emission =
// emissiveFactor * KHR_materials_emissive_strength. Whatever is approximated gets a
// warning naming the material.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "loaders/tinygltf_config.h"
#include "scene/scene.h"

namespace glslppm::gltf {

// Embedded images (data URIs, .glb buffer views), decoded while tinygltf parses.
struct DecodedImages {
    std::string file;
    std::map<int, Texture> textures;    // by images[] index
    std::map<int, std::string> errors;  // by images[] index: why it could not be decoded
};

// tinygltf's LoadImageDataFunction; user_data is a DecodedImages. Never fails the load: a
// bad image becomes a warning where a material uses it.
bool decode_image(tinygltf::Image* image, int image_index, std::string* err, std::string* warn,
                  int req_width, int req_height, const unsigned char* bytes, int size,
                  void* user_data);

// Appends one scene material per glTF material (same indices: the roots of their trees),
// then the trees' other parts, and the textures they use.
// External images are read relative to `base_dir` (none when it is empty).
void convert_materials(const tinygltf::Model& model, DecodedImages& images,
                       const std::string& base_dir, Scene& scene,
                       std::vector<std::string>& warnings);

}  // namespace glslppm::gltf
