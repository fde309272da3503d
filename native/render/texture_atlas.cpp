#include "render/texture_atlas.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "render/environment_map.h"

namespace glslppm {
namespace {

void check(const Texture& t, std::size_t k) {
    const std::string name = "textures[" + std::to_string(k) + "] '" + t.name + "'";
    if (t.width <= 0 || t.height <= 0)
        throw SceneError(name + ": width and height must be positive");
    const std::size_t want = std::size_t(t.width) * std::size_t(t.height) * 4;
    const bool bytes = !t.srgb8.empty(), floats = !t.linear.empty();
    if (bytes == floats)
        throw SceneError(name + ": exactly one of srgb8 and linear must hold the pixels");
    if ((bytes ? t.srgb8.size() : t.linear.size()) != want)
        throw SceneError(name + ": holds " +
                         std::to_string(bytes ? t.srgb8.size() : t.linear.size()) +
                         " values, width * height * 4 = " + std::to_string(want));
    for (float v : t.linear)
        if (!std::isfinite(v)) throw SceneError(name + ": holds NaN or Inf");
    for (int c = 0; c < 3; ++c)
        if (!std::isfinite(t.uv_map_u[c]) || !std::isfinite(t.uv_map_v[c]))
            throw SceneError(name + ": its uv map holds NaN or Inf");
    for (int c = 0; c < 4; ++c)
        if (!std::isfinite(t.position_map_u[c]) || !std::isfinite(t.position_map_v[c]))
            throw SceneError(name + ": its position map holds NaN or Inf");
}

// Whether two images hold the same pixels (so one rectangle serves both).
bool same_pixels(const Texture& a, const Texture& b) {
    return a.width == b.width && a.height == b.height && a.srgb8 == b.srgb8 &&
           a.linear == b.linear;
}

// Halves an image with a 2x2 box filter (in linear light for sRGB images).
Texture halve(const Texture& t) {
    Texture out;
    out.name = t.name;
    out.wrap = t.wrap;
    out.width = std::max(1, t.width / 2);
    out.height = std::max(1, t.height / 2);
    const bool bytes = !t.srgb8.empty();
    std::vector<float> pixels(std::size_t(out.width) * out.height * 4, 0.0f);
    for (int y = 0; y < out.height; ++y) {
        for (int x = 0; x < out.width; ++x) {
            glm::vec4 sum(0.0f);
            int n = 0;
            for (int yy = 2 * y; yy < std::min(t.height, 2 * y + 2); ++yy) {
                for (int xx = 2 * x; xx < std::min(t.width, 2 * x + 2); ++xx, ++n) {
                    const std::size_t i = 4 * (std::size_t(yy) * t.width + xx);
                    sum += glm::vec4(texel_rgb(t, xx, yy),
                                     bytes ? t.srgb8[i + 3] / 255.0f : t.linear[i + 3]);
                }
            }
            for (int c = 0; c < 4; ++c)
                pixels[4 * (std::size_t(y) * out.width + x) + c] = sum[c] / float(n);
        }
    }
    if (!bytes) {
        out.linear = std::move(pixels);
        return out;
    }
    // Back to sRGB bytes.
    out.srgb8.resize(pixels.size());
    for (std::size_t i = 0; i < pixels.size(); ++i) {
        const float v = std::clamp(pixels[i], 0.0f, 1.0f);
        const float e = (i % 4 == 3) ? v
                        : v <= 0.0031308f ? 12.92f * v
                                          : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
        out.srgb8[i] = static_cast<std::uint8_t>(std::lround(e * 255.0f));
    }
    return out;
}

// GpuTexture's info.z: the wrap, and the interpolation from TEXTURE_INTERPOLATION_SHIFT.
int texture_sampling(TextureWrap wrap, TextureInterpolation interpolation) {
    return static_cast<int>(wrap) | static_cast<int>(interpolation) << TEXTURE_INTERPOLATION_SHIFT;
}

}  // namespace

std::vector<GpuTexture> TextureAtlas::records() const {
    std::vector<GpuTexture> r;
    for (const AtlasPlacement& p : placements)
        r.push_back({{p.x, p.y, p.width, p.height},
                     {p.layer, p.is_float ? 1 : 0, texture_sampling(p.wrap, p.interpolation),
                      p.from_position ? kTextureFromPosition : kTextureFromUv},
                     p.from_position ? p.position_map_u : glm::vec4(p.uv_map_u, 0.0f),
                     p.from_position ? p.position_map_v : glm::vec4(p.uv_map_v, 0.0f)});
    if (r.empty()) r.push_back({});
    return r;
}

TextureAtlas pack_textures(const std::vector<Texture>& textures, const std::vector<bool>& used,
                           int max_texture_size, int max_layers) {
    TextureAtlas atlas;
    atlas.placements.resize(textures.size());
    std::vector<Texture> scaled(textures.size());
    std::vector<const Texture*> images(textures.size(), nullptr);
    // shared[k]: the texture whose rectangle k uses (itself unless an earlier one has the
    // same pixels).
    std::vector<std::size_t> shared(textures.size());
    for (std::size_t k = 0; k < textures.size(); ++k) {
        shared[k] = k;
        if (!used[k]) continue;
        check(textures[k], k);
        for (std::size_t j = 0; j < k; ++j) {
            if (images[j] && shared[j] == j && same_pixels(textures[j], textures[k])) {
                shared[k] = j;
                break;
            }
        }
        if (shared[k] != k) continue;
        images[k] = &textures[k];
        if (textures[k].width > max_texture_size || textures[k].height > max_texture_size) {
            scaled[k] = halve(textures[k]);
            while (scaled[k].width > max_texture_size || scaled[k].height > max_texture_size)
                scaled[k] = halve(scaled[k]);
            atlas.warnings.push_back("texture '" + textures[k].name + "' (" +
                                     std::to_string(textures[k].width) + "x" +
                                     std::to_string(textures[k].height) +
                                     ") is larger than this GPU's " +
                                     std::to_string(max_texture_size) + " texel limit: " +
                                     "downscaled to " + std::to_string(scaled[k].width) + "x" +
                                     std::to_string(scaled[k].height));
            images[k] = &scaled[k];
        }
    }
    // Shelf packing, tallest first, separately for each encoding, into layers as large as
    // the largest image and at least 1024 texels a side (a lone HDRI wastes nothing).
    for (int encoding = 0; encoding < 2; ++encoding) {
        std::vector<std::size_t> order;
        glm::ivec2 size(std::min(1024, max_texture_size));
        for (std::size_t k = 0; k < images.size(); ++k) {
            if (!images[k] || images[k]->linear.empty() != (encoding == 0)) continue;
            order.push_back(k);
            size = glm::max(size, glm::ivec2(images[k]->width, images[k]->height));
        }
        if (order.size() == 1) size = glm::ivec2(images[order[0]]->width, images[order[0]]->height);
        atlas.layer_size[encoding] = size;
        std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
            return images[a]->height > images[b]->height;
        });
        int layer = -1, x = 0, y = 0, shelf = 0;
        for (std::size_t k : order) {
            const Texture& t = *images[k];
            if (layer >= 0 && x + t.width > size.x) {
                x = 0;
                y += shelf;
                shelf = 0;
            }
            if (layer < 0 || y + t.height > size.y) {
                ++layer;
                x = y = shelf = 0;
            }
            atlas.placements[k] = {layer, x, y, t.width, t.height, encoding == 1};
            x += t.width;
            shelf = std::max(shelf, t.height);
        }
        atlas.layers[encoding] = layer + 1;
        if (layer + 1 > max_layers)
            throw SceneError("the scene's images need " + std::to_string(layer + 1) +
                             " layers of " + std::to_string(size.x) + "x" +
                             std::to_string(size.y) + " texels, more than this GPU's " +
                             std::to_string(max_layers) + ": use fewer or smaller images");
    }
    // Each texture's own wrap and uv map; a shared image's rectangle.
    for (std::size_t k = 0; k < textures.size(); ++k) {
        if (!used[k]) continue;
        AtlasPlacement& p = atlas.placements[k];
        if (shared[k] != k) p = atlas.placements[shared[k]];
        p.wrap = textures[k].wrap;
        p.interpolation = textures[k].interpolation;
        p.uv_map_u = textures[k].uv_map_u;
        p.uv_map_v = textures[k].uv_map_v;
        p.from_position = textures[k].from_position;
        p.position_map_u = textures[k].position_map_u;
        p.position_map_v = textures[k].position_map_v;
    }
    // Copy the pixels into their layers.
    auto layer_texels = [&](int e) {
        return std::size_t(atlas.layer_size[e].x) * std::size_t(atlas.layer_size[e].y);
    };
    atlas.srgb8.assign(std::size_t(atlas.layers[0]) * layer_texels(0) * 4, 0);
    atlas.linear.assign(std::size_t(atlas.layers[1]) * layer_texels(1) * 4, 0.0f);
    for (std::size_t k = 0; k < images.size(); ++k) {
        if (!images[k]) continue;
        const Texture& t = *images[k];
        const AtlasPlacement& p = atlas.placements[k];
        const int e = p.is_float ? 1 : 0;
        const std::size_t w = std::size_t(atlas.layer_size[e].x);
        for (int row = 0; row < t.height; ++row) {
            const std::size_t dst =
                (std::size_t(p.layer) * layer_texels(e) + std::size_t(p.y + row) * w + p.x) * 4;
            const std::size_t src = std::size_t(row) * t.width * 4;
            if (p.is_float)
                std::copy_n(&t.linear[src], std::size_t(t.width) * 4, &atlas.linear[dst]);
            else
                std::copy_n(&t.srgb8[src], std::size_t(t.width) * 4, &atlas.srgb8[dst]);
        }
    }
    return atlas;
}

}  // namespace glslppm
