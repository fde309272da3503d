// Planning a render before anything is allocated: its pass state's GPU bytes
// (render/memory_estimate.h) and, for frames larger than one storage buffer holds, its image
// tiles (render/tiled_render.h).
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <array>
#include <cstring>
#include <memory>
#include <optional>

#include "python/bindings.h"
#include "render/memory_estimate.h"
#include "render/renderer.h"
#include "render/tiled_render.h"

namespace py = pybind11;

namespace glslppm {
namespace {

py::tuple tile_tuple(const Tile& t) { return py::make_tuple(t.x, t.y, t.width, t.height); }

py::dict plan_dict(const TilePlan& plan) {
    py::list tiles;
    for (const Tile& t : plan.tiles) tiles.append(tile_tuple(t));
    py::dict d;
    d["tiles"] = tiles;
    d["gpu_bytes_per_pixel"] = plan.gpu_bytes_per_pixel;
    d["block_bytes_per_pixel"] = plan.block_bytes_per_pixel;
    d["largest_block"] = plan.largest_block;
    return d;
}

py::dict estimate_dict(const PassStateShape& shape, std::int64_t largest) {
    const PassStateBytes b = pass_state_bytes(shape);
    py::dict buffers;
    buffers["visible_points"] = b.visible_points;
    buffers["pixel_statistics"] = b.pixel_stats;
    buffers["direct_light"] = b.direct_light;
    buffers["film"] = b.film;
    buffers["render_passes"] = b.pass_films;
    buffers["light_splats"] = b.light_splats;
    buffers["photon_paths"] = b.photon_paths;
    buffers["photons"] = b.photons;
    buffers["hash_cells"] = b.hash_cells;
    buffers["sorted_photons"] = b.sorted_photons;
    buffers["generator_states"] = b.rng_states;
    buffers["radius_statistics"] = b.radius_stats;
    py::dict d;
    d["gpu"] = b.total();
    d["buffers"] = buffers;
    d["gpu_bytes_per_pixel"] = b.bytes_per_pixel;
    d["block_bytes_per_pixel"] = b.block_bytes_per_pixel;
    d["gpu_bytes_per_photon"] = b.bytes_per_photon;
    d["largest_photon_buffer"] = b.largest_photon_buffer;
    d["light_tracing"] = shape.light_tracing;
    d["photon_steps_per_gather"] = shape.steps_per_gather;
    d["largest_block"] = largest;
    return d;
}

}  // namespace

void bind_tiles(py::module_& m) {
    m.def("memory_estimate", [](const RenderSettings& settings, const Scene* scene,
                                std::optional<std::int64_t> largest_block) {
        validate(settings);
        std::int64_t largest = 0;
        if (largest_block) {
            largest = *largest_block;
        } else {
            py::gil_scoped_release release;
            largest = devices_largest_block(settings);
        }
        return estimate_dict(pass_state_shape(settings, scene, largest), largest);
    }, py::arg("settings"), py::arg("scene") = nullptr, py::arg("largest_block") = py::none(),
       "The GPU bytes of the buffers a Renderer of these settings allocates for its passes "
       "(per pixel and per photon; the scene's own BVH, materials and images not counted), "
       "as it allocates them: {'gpu': total, 'buffers': {name: bytes}, "
       "'gpu_bytes_per_pixel', 'block_bytes_per_pixel', 'gpu_bytes_per_photon', "
       "'largest_photon_buffer' (the largest buffer image tiles do not split), ...}. scene "
       "decides light tracing's splats as the renderer does (without one they are counted "
       "wherever the settings allow light tracing); largest_block: the device's largest "
       "storage buffer in bytes (PPPM's stored photon steps depend on it; None: asked of the "
       "settings' devices). Equals a Renderer's stats()['pass_state_bytes'].");
    m.def("plan_tiles", [](const Scene& scene, const RenderSettings& settings) {
        TilePlan plan;
        {
            py::gil_scoped_release release;
            plan = plan_tiles(scene, settings);
        }
        return plan_dict(plan);
    }, py::arg("scene"), py::arg("settings"),
       "The image tiles (x, y, width, height; y from the top) that a render of this size "
       "needs on its device, decided before allocating: one when it fits. Also the per-pixel "
       "bytes and the device's largest storage buffer.");
    m.def("tile_render_inputs", [](const Scene& scene, const RenderSettings& settings,
                                   std::array<int, 4> tile) {
        const Tile t{tile[0], tile[1], tile[2], tile[3]};
        Scene s = scene;
        s.camera = tile_camera(scene.camera, settings, t);
        return py::make_tuple(s, tile_settings(settings, t));
    }, py::arg("scene"), py::arg("settings"), py::arg("tile"),
       "The (scene, settings) that render one tile (x, y, width, height) of the frame: its "
       "camera looks through the tile's window, with the whole frame's radius and streams.");
    m.def("for_each_tile", [](py::object scene_object, py::object settings_object,
                              const std::vector<std::array<int, 4>>& tiles, py::function visit) {
        if (!py::isinstance<Scene>(scene_object) ||
            !py::isinstance<RenderSettings>(settings_object))
            throw py::type_error("for_each_tile(scene, settings, tiles, visit): scene must be a "
                                 "Scene and settings a Settings");
        const Scene& scene = scene_object.cast<const Scene&>();
        const RenderSettings& settings = settings_object.cast<const RenderSettings&>();
        TilePlan plan;
        for (const auto& t : tiles) plan.tiles.push_back({t[0], t[1], t[2], t[3]});
        // The GIL stays held: the loop is the caller's, each visit Python's own work.
        return for_each_tile(scene, settings, plan, [&](const TileJob& job) {
            // One tile: the caller's own objects (the frame as it is).
            const bool single = job.count == 1;
            const py::object keep = visit(
                job.index, job.count, tile_tuple(job.tile),
                single ? scene_object : py::cast(job.scene),
                single ? settings_object : py::cast(job.settings));
            return keep.is_none() || keep.cast<bool>();
        });
    }, py::arg("scene"), py::arg("settings"), py::arg("tiles"), py::arg("visit"),
       "The one tile loop (render_tiled runs it too): visit(index, count, (x, y, w, h), "
       "tile_scene, tile_settings) for each of `tiles` (plan_tiles' 'tiles') in order, with "
       "the scene and settings that render that tile (tile_render_inputs; with one tile, "
       "scene and settings themselves). Returning False stops before the next tile. Returns "
       "the tiles visited. ValueError for a tile outside the frame.");
    m.def("render_tiled", [](const Scene& scene, const RenderSettings& settings,
                                                  int passes, py::object on_tile,
                                                  std::shared_ptr<CancelFlag> cancel) {
        TiledImage image;
        {
            py::gil_scoped_release release;
            const TilePlan plan = plan_tiles(scene, settings);
            TileDone done;
            if (!on_tile.is_none()) {
                done = [&](std::size_t index, const Tile& t, const std::vector<float>& rgba) {
                    py::gil_scoped_acquire acquire;
                    py::array_t<float> a({t.height, t.width, 4});
                    std::memcpy(a.mutable_data(), rgba.data(), rgba.size() * sizeof(float));
                    const py::object keep = on_tile(index, tile_tuple(t), a);
                    return keep.is_none() || keep.cast<bool>();
                };
            }
            image = render_tiled(scene, settings, passes, plan, done, cancel.get());
        }
        py::array_t<float> out({settings.height, settings.width, 4});
        std::memcpy(out.mutable_data(), image.rgba.data(), image.rgba.size() * sizeof(float));
        py::dict stats = stats_dict(image.stats);
        stats["plan"] = plan_dict(image.plan);
        return py::make_tuple(out, stats);
    }, py::arg("scene"), py::arg("settings"), py::arg("passes"), py::arg("on_tile") = py::none(),
       py::arg("cancel") = nullptr,
       "Renders the frame as the tiles plan_tiles gives, `passes` SPPM passes each (each tile "
       "traces its own photons: time grows with the tile count). on_tile(index, (x, y, w, h), "
       "rgba) after each; returning False stops. Returns (rgba, stats).");
}

}  // namespace glslppm
