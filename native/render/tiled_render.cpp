#include "render/tiled_render.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

#include "gl/device_limits.h"
#include "render/memory_estimate.h"
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

std::int64_t devices_largest_block(const RenderSettings& settings) {
    // With several workers (settings.devices) every device holds the whole tile: the
    // smallest of their limits.
    const std::vector<int> devices =
        settings.devices.empty() ? std::vector<int>{settings.device} : settings.devices;
    std::int64_t largest = 0;
    for (int device : devices) {
        const std::int64_t value = gl::device_limits(device).max_storage_buffer_bytes;
        if (value > 0) largest = largest > 0 ? std::min<std::int64_t>(largest, value) : value;
    }
    return largest;
}

TilePlan plan_tiles(const Scene& scene, const RenderSettings& settings) {
    validate(settings);
    const std::int64_t largest = devices_largest_block(settings);
    // The per-pixel bytes the renderer allocates (render/memory_estimate.h): visible points,
    // statistics, direct light, film, the render passes' films (the largest block may be
    // theirs) and light tracing's splats where the scene has a mirror or glass to trace.
    const PassStateBytes bytes = pass_state_bytes(pass_state_shape(settings, &scene, largest));
    return plan_tiles(settings.width, settings.height, bytes.block_bytes_per_pixel,
                      bytes.bytes_per_pixel, capped_block_bytes(largest, settings));
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

namespace {

// A tile's stats into the frame's: counts and times add up, sizes take the largest, the
// mean radius is weighted by the tile's pixels.
void add_tile_stats(RenderStats& sum, const RenderStats& s, std::size_t t, const Tile& tile,
                    const RenderSettings& settings) {
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
        sum.pass_state_bytes = std::max(sum.pass_state_bytes, s.pass_state_bytes);
        sum.max_radius = std::max(sum.max_radius, s.max_radius);
        // Every tile runs the same pass indices (the same pass_ranges) on the same
        // workers: their passes and times add up.
        for (std::size_t k = 0; k < sum.devices.size() && k < s.devices.size(); ++k) {
            sum.devices[k].passes += s.devices[k].passes;
            sum.devices[k].seconds += s.devices[k].seconds;
        }
    }
    const double share =
        double(tile.width) * tile.height / (double(settings.width) * settings.height);
    if (t == 0) sum.mean_radius = 0.0;
    sum.mean_radius += s.mean_radius * share;
}

}  // namespace

std::size_t for_each_tile(const Scene& scene, const RenderSettings& settings, const TilePlan& plan,
                          const TileVisit& visit, const CancelFlag* cancel) {
    for (std::size_t t = 0; t < plan.tiles.size(); ++t) {
        const Tile& tile = plan.tiles[t];
        if (tile.x < 0 || tile.y < 0 || tile.width < 1 || tile.height < 1 ||
            tile.x + tile.width > settings.width || tile.y + tile.height > settings.height)
            throw std::invalid_argument(
                "tile " + std::to_string(t) + " (" + std::to_string(tile.x) + ", " +
                std::to_string(tile.y) + ", " + std::to_string(tile.width) + "x" +
                std::to_string(tile.height) + ") does not lie within the " +
                std::to_string(settings.width) + "x" + std::to_string(settings.height) + " frame");
    }
    const bool single = plan.tiles.size() == 1;
    Scene tile_scene;
    if (!single) tile_scene = scene;  // a copy whose camera each tile replaces
    for (std::size_t t = 0; t < plan.tiles.size(); ++t) {
        throw_if_cancelled(cancel);
        const Tile& tile = plan.tiles[t];
        // One tile renders the scene as it is: bit for bit the untiled image.
        if (single) {
            if (!visit({t, 1, tile, scene, settings})) return t + 1;
            continue;
        }
        tile_scene.camera = tile_camera(scene.camera, settings, tile);
        const RenderSettings band = tile_settings(settings, tile);
        if (!visit({t, plan.tiles.size(), tile, tile_scene, band})) return t + 1;
    }
    return plan.tiles.size();
}

TiledImage render_tiled(const Scene& scene, const RenderSettings& settings, int passes,
                        const TilePlan& plan, const TileDone& on_tile, const CancelFlag* cancel) {
    if (passes < 1) throw std::invalid_argument("passes: must be at least 1");
    TiledImage out;
    out.plan = plan;
    out.rgba.assign(std::size_t(settings.width) * settings.height * 4, 0.0f);
    out.passes.assign(settings.passes.size(), out.rgba);
    out.light_groups.assign(scene.light_groups.size(), out.rgba);
    // A tile's rows of a height x width x 4 image into the frame's.
    auto place = [&](std::vector<float>& frame, const std::vector<float>& image, const Tile& tile) {
        for (int row = 0; row < tile.height; ++row)
            std::memcpy(&frame[(std::size_t(tile.y + row) * settings.width + tile.x) * 4],
                        &image[std::size_t(row) * tile.width * 4],
                        std::size_t(tile.width) * 4 * sizeof(float));
    };
    // One tile: a whole SPPM render of its rows, placed into the frame.
    auto render_tile = [&](const TileJob& job) {
        const std::size_t t = job.index;
        const Tile& tile = job.tile;
        Renderer renderer(job.scene, job.settings, cancel);
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
        const std::vector<std::vector<float>> groups = renderer.light_group_passes();
        for (std::size_t g = 0; g < groups.size(); ++g) place(out.light_groups[g], groups[g], tile);
        add_tile_stats(out.stats, s, t, tile, settings);
        if (on_tile && !on_tile(t, tile, film) && t + 1 < job.count) throw Cancelled();
        return true;
    };
    for_each_tile(scene, settings, plan, render_tile, cancel);
    const bool single = plan.tiles.size() == 1;
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
