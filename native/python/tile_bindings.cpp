// Frames larger than one storage buffer holds, as image tiles (render/tiled_render.h).
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <array>
#include <cstring>
#include <memory>

#include "python/bindings.h"
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

}  // namespace

void bind_tiles(py::module_& m) {
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
