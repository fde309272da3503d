// A frame larger than one storage buffer holds (llvmpipe and some GPUs allow 128 MiB per
// block: about 2.8 Mpixels of visible points) rendered as image tiles one after another.
// Each tile is a whole SPPM render of a band of rows, through the camera's render region:
// its own photon passes (the time grows with the tile count), the same seed, and the whole
// frame's automatic radius and random streams (native/render/scene_preparation.h
// frame_camera), so that tiles join without seams.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "render/renderer.h"
#include "render/settings.h"
#include "scene/cancel.h"
#include "scene/scene.h"

namespace glslppm {

struct Tile {
    int x = 0, y = 0;  // the first pixel, in the image (row 0 at the top)
    int width = 0, height = 0;
};

struct TilePlan {
    std::size_t block_bytes_per_pixel = 0;  // the largest per-pixel buffer (visible points)
    std::size_t gpu_bytes_per_pixel = 0;    // every per-pixel buffer together
    std::size_t largest_block = 0;          // what one buffer may hold; 0: no limit known
    std::vector<Tile> tiles;                // row-major, covering the image once
};

// The storage-buffer limit the per-pixel buffers work to: the driver's, capped by
// settings.max_block_bytes where that is set. 0: no limit known.
std::size_t capped_block_bytes(std::int64_t driver_largest, const RenderSettings& settings);

// Bands of whole rows, as few as fit (every band's visible points within `largest_block`),
// their heights differing by at most one row. One tile when the image fits.
TilePlan plan_tiles(int width, int height, std::size_t block_bytes_per_pixel,
                    std::size_t gpu_bytes_per_pixel, std::size_t largest_block);

// The devices' (settings.device, or each of settings.devices) largest storage buffer, the
// smallest of them; 0: none known. Asks through a short-lived EGL context on a GL thread of
// its own (gl::GlError when none opens).
std::int64_t devices_largest_block(const RenderSettings& settings);

// The plan for a scene on its device, decided before anything is allocated, from the
// pass state's bytes (render/memory_estimate.h) and devices_largest_block.
TilePlan plan_tiles(const Scene& scene, const RenderSettings& settings);

// One tile's camera and settings: the tile's window in the whole frame, composed with the
// camera's own render region where it has one.
Camera tile_camera(const Camera& camera, const RenderSettings& settings, const Tile& tile);
RenderSettings tile_settings(const RenderSettings& settings, const Tile& tile);

// One tile as for_each_tile hands it over: its index among `count`, its place, and the
// scene and settings that render it (tile_camera, tile_settings; with one tile the frame's
// own scene and settings).
struct TileJob {
    std::size_t index = 0, count = 0;
    const Tile& tile;
    const Scene& scene;
    const RenderSettings& settings;
};

// The one tile loop: render_tiled (glslppm-render, the module's render_tiled) and the
// add-on (its streaming of each tile into Blender's result, through the module's
// for_each_tile) both run it. Calls `visit` for every tile of `plan`, in its order; a visit
// returning false stops before the next tile. Returns the tiles visited. Setting `cancel`
// stops before the next tile (Cancelled). std::invalid_argument for a plan whose tiles do
// not lie within the frame.
using TileVisit = std::function<bool(const TileJob&)>;
std::size_t for_each_tile(const Scene& scene, const RenderSettings& settings,
                          const TilePlan& plan, const TileVisit& visit,
                          const CancelFlag* cancel = nullptr);

struct TiledImage {
    std::vector<float> rgba;  // height x width x 4, row 0 at the top
    // settings.passes in their order, each as Renderer::render_pass gives it for the frame.
    std::vector<std::vector<float>> passes;
    // Every light group's pass (Scene::light_groups), as Renderer::light_group_passes gives
    // them for the frame.
    std::vector<std::vector<float>> light_groups;
    RenderStats stats;        // summed over the tiles (passes: each tile's)
    TilePlan plan;
};

// Called after each tile with its index, place and RGBA (tile.height x tile.width x 4);
// returning false stops before the next tile.
using TileDone = std::function<bool(std::size_t, const Tile&, const std::vector<float>&)>;

// Renders every tile of `plan` for `passes` passes each. Setting `cancel` stops within a
// pass of the tile in progress (Cancelled); the tiles done so far have been reported.
TiledImage render_tiled(const Scene& scene, const RenderSettings& settings, int passes,
                        const TilePlan& plan, const TileDone& on_tile = {},
                        const CancelFlag* cancel = nullptr);

}  // namespace glslppm
