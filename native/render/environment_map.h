// An equirectangular environment map's sampling distribution: photons leave the
// environment in proportion to its radiance, so that a small bright sun in an HDRI sends
// most photons and casts sharp caustics (Pharr et al., PBRT 3rd ed., section 14.2.4:
// piecewise-constant 2-D distribution, marginal over rows and conditional per row, with
// each texel weighted by sin(theta) for the solid angle it covers).
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace glslppm {

// sRGB-encoded byte to linear (IEC 61966-2-1), the decode shaders/common/textures.glsl
// applies to filtered sRGB bytes.
float srgb_to_linear(std::uint8_t value);

// Linear RGB of texel (x, y) of a texture (row 0 at the bottom).
glm::vec3 texel_rgb(const Texture& texture, int x, int y);

struct EnvironmentMap {
    int width = 0, height = 0;  // of the distribution (the map's texels, possibly pooled)
    // GPU layout (shaders/common/environment.glsl): height + 1 marginal CDF values over the
    // rows (row 0 = v = 0, the bottom, theta = pi), then per row width + 1 conditional CDF
    // values; each CDF starts at 0 and ends at 1.
    std::vector<float> cdf;
    // Integral of the radiance over the sphere (W / m^2 / sr * sr), per channel: the
    // environment's power through a unit disc facing it... over all directions.
    glm::vec3 integral{0.0f};
};

// The distribution of `texture` scaled by `color`. Each texel's weight is the largest
// luminance of it and its 8 neighbours (bilinear filtering spreads a texel's radiance over
// its neighbours, and the pdf must be positive wherever the filtered radiance is) times
// sin(theta). Maps larger than 2048 x 1024 are pooled by an integer factor.
EnvironmentMap build_environment_map(const Texture& texture, glm::vec3 color);

}  // namespace glslppm
