// Packing the scene's images into two 2-D array textures (8-bit sRGB and float), so that
// any number of images fits in two sampler bindings. Each image keeps its own rectangle;
// the shaders filter (bilinear, or the one nearest texel) with texelFetch inside it, so
// wrapping never bleeds into a neighbour (shaders/common/textures.glsl).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "render/gpu_layout.h"
#include "scene/scene.h"

namespace glslppm {

struct AtlasPlacement {
    int layer = 0, x = 0, y = 0, width = 0, height = 0;
    bool is_float = false;
    TextureWrap wrap = TextureWrap::Repeat;
    TextureInterpolation interpolation = TextureInterpolation::Linear;
    glm::vec3 uv_map_u{1.0f, 0.0f, 0.0f}, uv_map_v{0.0f, 1.0f, 0.0f};
    bool from_position = false;
    glm::vec4 position_map_u{0.0f}, position_map_v{0.0f};
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

    // The GPU records (GpuTexture, render/gpu_layout.h), one per texture.
    std::vector<GpuTexture> records() const;
};

// Throws SceneError naming the texture when an image is malformed. `used[k]` says whether
// texture k is referenced; unused images are not packed. Textures with the same pixels (one
// image under several wraps or uv maps) share one rectangle. Images larger than
// max_texture_size are halved (2x2 box filter) until they fit, with a warning.
TextureAtlas pack_textures(const std::vector<Texture>& textures, const std::vector<bool>& used,
                           int max_texture_size, int max_layers);

}  // namespace glslppm
