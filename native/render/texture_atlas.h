// Packing the scene's images into two 2-D array textures (8-bit sRGB and float), so that
// any number of images fits in two sampler bindings. Each image keeps its own rectangle;
// the shaders filter bilinearly with texelFetch inside it, so wrapping never bleeds into a
// neighbour (shaders/common/textures.glsl).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace glslppm {

struct AtlasPlacement {
    int layer = 0, x = 0, y = 0, width = 0, height = 0;
    bool is_float = false;
    TextureWrap wrap = TextureWrap::Repeat;
};

struct TextureAtlas {
    // Per encoding ([0] sRGB8, [1] float): layer width and height, and layer count.
    glm::ivec2 layer_size[2] = {glm::ivec2(1), glm::ivec2(1)};
    int layers[2] = {0, 0};
    std::vector<AtlasPlacement> placements;  // one per scene texture (unused ones: width 0)
    // Layer pixels: sRGB8 RGBA bytes, float RGBA; layer-major, row 0 first.
    std::vector<std::uint8_t> srgb8;
    std::vector<float> linear;
    std::vector<std::string> warnings;  // images downscaled to fit the GPU

    // The GPU record (shaders/common/textures.glsl): 2 ivec4 per texture:
    // (x, y, width, height), (layer, float 0/1, wrap, 0).
    std::vector<glm::ivec4> records() const;
};

// Throws SceneError naming the texture when an image is malformed. `used[k]` says whether
// texture k is referenced; unused images are not packed. Images larger than
// max_texture_size are halved (2x2 box filter) until they fit, with a warning.
TextureAtlas pack_textures(const std::vector<Texture>& textures, const std::vector<bool>& used,
                           int max_texture_size, int max_layers);

}  // namespace glslppm
