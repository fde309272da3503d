#include "render/tiled_render.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "gl/device_limits.h"
#include "render/scene_preparation.h"
#include "scene/scene_hash.h"

namespace glslppm {

std::size_t capped_block_bytes(std::int64_t driver_largest, const RenderSettings& settings) {
    std::size_t limit = driver_largest > 0 ? static_cast<std::size_t>(driver_largest) : 0;
    if (settings.max_block_bytes > 0) {
        const auto cap = static_cast<std::size_t>(settings.max_block_bytes);
        limit = limit ? std::min(limit, cap) : cap;
    }
    return limit;
}

TilePlan plan_tiles(int width, int height, std::size_t block_bytes_per_pixel,
                    std::size_t gpu_bytes_per_pixel, std::size_t largest_block) {
    TilePlan plan;
    plan.block_bytes_per_pixel = block_bytes_per_pixel;
    plan.gpu_bytes_per_pixel = gpu_bytes_per_pixel;
    plan.largest_block = largest_block;
    int bands = 1;
    if (largest_block > 0) {
        const std::size_t row = std::size_t(width) * block_bytes_per_pixel;
        const std::size_t rows = largest_block / row;
        if (rows < 1)
            throw std::invalid_argument(
                "one row of " + std::to_string(width) + " pixels needs " + std::to_string(row) +
                " bytes of visible points, more than this GPU's largest " + "storage buffer (" +
                std::to_string(largest_block) + " bytes)");
        bands = static_cast<int>((std::size_t(height) + rows - 1) / rows);
    }
    // Equal bands (heights differ by at most one row) rather than full ones and a thin rest.
    for (int b = 0, y = 0; b < bands; ++b) {
        const int rows = height / bands + (b < height % bands ? 1 : 0);
        plan.tiles.push_back({0, y, width, rows});
        y += rows;
    }
    return plan;
}

TilePlan plan_tiles([[maybe_unused]] const Scene& scene, const RenderSettings& settings) {
    validate(settings);
    const std::size_t point_vec4s = kVisiblePointVec4;
    // Visible points (4 vec4), pixel statistics (2), direct light (2), film (1):
    // native/render/renderer.cpp allocates them.
    // With render passes, their films (render/render_passes.h) too: the largest block may be
    // theirs.
    const PassLayout passes =
        pass_layout(settings.passes, settings.direct_light == DirectLight::Photons);
    const std::size_t pass_bytes = std::size_t(passes.stride) * 16;
    const std::size_t point_bytes = std::max<std::size_t>(point_vec4s * 16, pass_bytes);
    // Light tracing's splats (kLightSplatBytes, no more than the smallest visible point) where
    // the scene has a mirror or glass to trace (render/scene_features.cpp decides for good).
    bool specular = false;
    for (const Material& m : scene.materials)
        specular |= m.kind == MaterialKind::Conductor || m.kind == MaterialKind::Dielectric;
    const std::size_t splat_bytes = settings.light_tracing && specular ? kLightSplatBytes : 0;
    const std::size_t pixel_bytes =
        point_vec4s * 16 + (2 + 2 + 1) * 16 + pass_bytes + splat_bytes;
    // With several workers (settings.devices) every device holds the whole tile: the
    // smallest of their limits.
    const std::vector<int> devices =
        settings.devices.empty() ? std::vector<int>{settings.device} : settings.devices;
    std::int64_t largest = 0;
    for (int device : devices) {
        const std::int64_t value = gl::device_limits(device).max_storage_buffer_bytes;
        if (value > 0) largest = largest > 0 ? std::min<std::int64_t>(largest, value) : value;
    }
    return plan_tiles(settings.width, settings.height, point_bytes, pixel_bytes,
                      capped_block_bytes(largest, settings));
}

Camera tile_camera(const Camera& camera, const RenderSettings& settings, const Tile& tile) {
    Camera c = camera;
    if (camera.full_width == 0) {
        c.full_width = settings.width;
        c.full_height = settings.height;
    }
    c.region_x = camera.region_x + tile.x;
    c.region_y = camera.region_y + tile.y;
    return c;
}

RenderSettings tile_settings(const RenderSettings& settings, const Tile& tile) {
    RenderSettings s = settings;
    s.width = tile.width;
    s.height = tile.height;
    return s;
}

TiledImage render_tiled(const Scene& scene, const RenderSettings& settings, int passes,
                        const TilePlan& plan, const TileDone& on_tile, const CancelFlag* cancel) {
    if (passes < 1) throw std::invalid_argument("passes: must be at least 1");
    TiledImage out;
    out.plan = plan;
    out.rgba.assign(std::size_t(settings.width) * settings.height * 4, 0.0f);
    out.passes.assign(settings.passes.size(), out.rgba);
    // A tile's rows of a height x width x 4 image into the frame's.
    auto place = [&](std::vector<float>& frame, const std::vector<float>& image, const Tile& tile) {
        for (int row = 0; row < tile.height; ++row)
            std::memcpy(&frame[(std::size_t(tile.y + row) * settings.width + tile.x) * 4],
                        &image[std::size_t(row) * tile.width * 4],
                        std::size_t(tile.width) * 4 * sizeof(float));
    };
    const bool single = plan.tiles.size() == 1;
    Scene tile_scene;
    if (!single) tile_scene = scene;  // a copy whose camera each tile replaces
    for (std::size_t t = 0; t < plan.tiles.size(); ++t) {
        throw_if_cancelled(cancel);
        const Tile& tile = plan.tiles[t];
        // One tile renders the scene as it is: bit for bit the untiled image.
        if (!single) tile_scene.camera = tile_camera(scene.camera, settings, tile);
        Renderer renderer(single ? scene : tile_scene,
                          single ? settings : tile_settings(settings, tile), cancel);
        // A few passes at a time, so that a cancel stops within the tile.
        for (int done = 0; done < passes;) {
            throw_if_cancelled(cancel);
            done += renderer.run(std::min(4, passes - done));
        }
        const std::vector<float> film = renderer.film();
        const RenderStats s = renderer.stats();
        place(out.rgba, film, tile);
        if (!settings.passes.empty()) {
            const std::vector<std::vector<float>> images = renderer.render_passes(settings.passes);
            for (std::size_t k = 0; k < images.size(); ++k) place(out.passes[k], images[k], tile);
        }
        RenderStats& sum = out.stats;
        if (t == 0) {
            sum = s;
        } else {
            sum.photons_emitted += s.photons_emitted;
            sum.rays += s.rays;
            sum.seconds += s.seconds;
            sum.eye_seconds += s.eye_seconds;
            sum.photon_seconds += s.photon_seconds;
            sum.hash_seconds += s.hash_seconds;
            sum.gather_seconds += s.gather_seconds;
            sum.compile_seconds += s.compile_seconds;
            sum.bvh_seconds += s.bvh_seconds;
            sum.programs_compiled += s.programs_compiled;
            sum.programs_reused += s.programs_reused;
            sum.gpu_bytes = std::max(sum.gpu_bytes, s.gpu_bytes);
            sum.max_radius = std::max(sum.max_radius, s.max_radius);
            // Every tile runs the same pass indices (the same pass_ranges) on the same
            // workers: their passes and times add up.
            for (std::size_t k = 0; k < sum.devices.size() && k < s.devices.size(); ++k) {
                sum.devices[k].passes += s.devices[k].passes;
                sum.devices[k].seconds += s.devices[k].seconds;
            }
        }
        // The mean radius weighted by each tile's pixels.
        const double share =
            double(tile.width) * tile.height / (double(settings.width) * settings.height);
        if (t == 0) sum.mean_radius = 0.0;
        sum.mean_radius += s.mean_radius * share;
        if (on_tile && !on_tile(t, tile, film) && t + 1 < plan.tiles.size()) throw Cancelled();
    }
    RenderStats& sum = out.stats;
    sum.tiles = static_cast<int>(plan.tiles.size());
    sum.gpu_bytes_per_pixel = plan.gpu_bytes_per_pixel;
    sum.photons_per_second = sum.seconds > 0 ? double(sum.photons_emitted) / sum.seconds : 0.0;
    sum.rays_per_second = sum.seconds > 0 ? double(sum.rays) / sum.seconds : 0.0;
    for (DeviceStats& d : sum.devices)
        d.passes_per_second = d.seconds > 0 ? double(d.passes) / d.seconds : 0.0;
    // The whole frame's camera, not the first tile's window (farm_attributes).
    if (!single) sum.scene_hash = scene_hash_hex(scene, cancel);
    return out;
}

}  // namespace glslppm
