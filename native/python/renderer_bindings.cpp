// Renderer: runs passes in steps with the GIL released, films and passes back as numpy
// arrays; CancelFlag; the catalog of render passes.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <memory>
#include <mutex>
#include <optional>
#include <span>
#include <thread>

#include "image/exr.h"
#include "python/bindings.h"
#include "python/numpy_arrays.h"
#include "render/farm_merge.h"
#include "render/render_passes.h"
#include "render/renderer.h"
#include "scene/scene_hash.h"

namespace glslppm {
namespace {

// The Python-facing renderer: close() frees the GPU now rather than at garbage collection.
// Each call holds its own reference, so close() on one thread while run() goes on in another
// cancels that run and frees the GPU when it returns, never under it.
class PyRenderer {
public:
    PyRenderer(const Scene& scene, const RenderSettings& settings, const CancelFlag* cancel)
        : renderer_(std::make_shared<Renderer>(scene, settings, cancel)) {}
    std::shared_ptr<Renderer> get() {
        std::lock_guard lock(mutex_);
        if (!renderer_) throw std::runtime_error("this Renderer was closed");
        return renderer_;
    }
    void close() {
        std::shared_ptr<Renderer> last;
        {
            std::lock_guard lock(mutex_);
            last = std::move(renderer_);
        }
        if (last) last->stop();
    }
    bool closed() const {
        std::lock_guard lock(mutex_);
        return !renderer_;
    }
    // Tests only: closes, letting go of this handle's reference on a thread Python has never
    // seen (as Blender's render job threads are), while the caller keeps the GIL released.
    void close_on_native_thread() {
        std::shared_ptr<Renderer> last;
        {
            std::lock_guard lock(mutex_);
            last = std::move(renderer_);
        }
        if (last) last->stop();
        std::thread([owned = std::move(last)]() mutable { owned.reset(); }).join();
    }

private:
    mutable std::mutex mutex_;
    std::shared_ptr<Renderer> renderer_;
};

// Renderer.render_pass(es): each pass as a height x width x channels array, resolved
// together (one read back of the pass films); bottom_up: rows from the bottom, as film()
// gives Combined for Blender, flipped in the copy that drops the fourth channel.
py::dict render_pass_arrays(PyRenderer& r, const std::vector<std::string>& names,
                            bool bottom_up) {
    std::vector<RenderPass> wanted;
    for (const std::string& name : names) wanted.push_back(parse_render_pass(name));
    std::vector<std::vector<float>> images;
    const std::shared_ptr<Renderer> renderer = r.get();
    {
        py::gil_scoped_release release;
        images = renderer->render_passes(wanted);
    }
    const RenderSettings& s = renderer->settings();
    py::dict out;
    for (std::size_t k = 0; k < wanted.size(); ++k) {
        const int channels = render_pass_info(wanted[k]).channels;
        py::array_t<float> a({s.height, s.width, channels});
        float* dst = a.mutable_data();
        const float* src = images[k].data();
        const std::size_t row = std::size_t(s.width);
        for (std::size_t y = 0; y < std::size_t(s.height); ++y) {
            const std::size_t from = (bottom_up ? std::size_t(s.height) - 1 - y : y) * row;
            for (std::size_t x = 0; x < row; ++x)
                for (int c = 0; c < channels; ++c)
                    dst[(y * row + x) * channels + c] = src[4 * (from + x) + c];
        }
        out[py::str(names[k])] = a;
    }
    return out;
}

}  // namespace

// Renderer.light_group_passes: {group name: height x width x 3}, as render_passes gives a pass.
py::dict light_group_arrays(PyRenderer& r, bool bottom_up) {
    const std::shared_ptr<Renderer> renderer = r.get();
    std::vector<std::vector<float>> images;
    {
        py::gil_scoped_release release;
        images = renderer->light_group_passes();
    }
    const RenderSettings& s = renderer->settings();
    py::dict out;
    const std::size_t row = std::size_t(s.width);
    for (std::size_t k = 0; k < images.size(); ++k) {
        py::array_t<float> a({s.height, s.width, 3});
        float* dst = a.mutable_data();
        for (std::size_t y = 0; y < std::size_t(s.height); ++y) {
            const std::size_t from = (bottom_up ? std::size_t(s.height) - 1 - y : y) * row;
            for (std::size_t x = 0; x < row; ++x)
                for (int c = 0; c < 3; ++c)
                    dst[(y * row + x) * 3 + c] = images[k][4 * (from + x) + c];
        }
        out[py::str(renderer->light_groups()[k])] = a;
    }
    return out;
}

py::dict stats_dict(const RenderStats& s) {
    py::dict d;
    d["passes"] = s.passes;
    d["photons_emitted"] = s.photons_emitted;
    d["rays"] = s.rays;
    d["seconds"] = s.seconds;
    d["photons_per_second"] = s.photons_per_second;
    d["rays_per_second"] = s.rays_per_second;
    d["mean_radius"] = s.mean_radius;
    d["max_radius"] = s.max_radius;
    d["initial_radius"] = s.initial_radius;
    d["renderer"] = s.renderer;
    d["variant"] = s.variant;
    d["direct_light"] = s.direct_light;
    d["estimator"] = s.estimator;
    d["scene_hash"] = s.scene_hash;
    d["radius_floor"] = s.radius_floor;
    py::list ranges;
    for (const auto& [first, end] : s.pass_ranges) ranges.append(py::make_tuple(first, end));
    d["pass_ranges"] = ranges;
    py::list devices;
    for (const DeviceStats& ds : s.devices) {
        py::dict e;
        e["device"] = ds.device;
        e["renderer"] = ds.renderer;
        e["passes"] = ds.passes;
        e["seconds"] = ds.seconds;
        e["passes_per_second"] = ds.passes_per_second;
        devices.append(e);
    }
    d["devices"] = devices;
    d["triangles"] = s.triangles;
    d["degenerate_dropped"] = s.degenerate_dropped;
    d["instancing"] = s.instancing;
    d["instancing_reason"] = s.instancing_reason;
    d["motion"] = s.motion;
    d["moving_instances"] = s.moving_instances;
    d["motion_refit_seconds"] = s.motion_refit_seconds;
    d["instances"] = s.instances;
    d["instanced_triangles"] = s.instanced_triangles;
    d["emitters"] = s.emitters;
    d["bvh_seconds"] = s.bvh_seconds;
    d["bvh_bytes_per_triangle"] = s.bvh_bytes_per_triangle;
    d["gpu_bytes"] = s.gpu_bytes;
    d["gpu_bytes_per_pixel"] = s.gpu_bytes_per_pixel;
    d["gpu_bytes_per_photon"] = s.gpu_bytes_per_photon;
    d["pass_state_bytes"] = s.pass_state_bytes;
    d["tiles"] = s.tiles;
    d["warnings"] = s.warnings;
    d["programs_compiled"] = s.programs_compiled;
    d["programs_reused"] = s.programs_reused;
    d["compile_seconds"] = s.compile_seconds;
    d["camera_updates"] = s.camera_updates;
    d["table_updates"] = s.table_updates;
    d["film_resets"] = s.film_resets;
    d["eye_seconds"] = s.eye_seconds;
    d["photon_seconds"] = s.photon_seconds;
    d["hash_seconds"] = s.hash_seconds;
    d["gather_seconds"] = s.gather_seconds;
    return d;
}

void bind_renderer(py::module_& m) {
    // Set from any thread while a Renderer is being constructed with it: the construction
    // (BVH build, GL set-up) stops within milliseconds and raises Cancelled.
    py::class_<CancelFlag, std::shared_ptr<CancelFlag>>(m, "CancelFlag")
        .def(py::init([] { return std::make_shared<CancelFlag>(false); }))
        .def("set", [](CancelFlag& flag) { flag = true; })
        .def("clear", [](CancelFlag& flag) { flag = false; })
        .def_property_readonly("is_set", [](const CancelFlag& flag) { return flag.load(); });

    py::class_<PyRenderer>(m, "Renderer")
        .def(py::init([](const Scene& scene, const RenderSettings& settings,
                         std::shared_ptr<CancelFlag> cancel) {
                 py::gil_scoped_release release;
                 return std::make_unique<PyRenderer>(scene, settings, cancel.get());
             }),
             py::arg("scene"), py::arg("settings"), py::arg("cancel") = nullptr)
        .def("run", [](PyRenderer& r, int passes) {
            if (passes < 0) throw py::value_error("passes: must be >= 0");
            py::gil_scoped_release release;
            return r.get()->run(passes);
        }, py::arg("passes") = 1,
        "Runs that many passes; returns how many ran (fewer after cancel() or close()).")
        .def("run_passes", [](PyRenderer& r, std::vector<std::uint64_t> indices) {
            py::gil_scoped_release release;
            return r.get()->run_passes(indices);
        }, py::arg("indices"),
        "PPPM: runs exactly these pass indices over the workers; returns how many ran.")
        .def("farm_attributes", [](PyRenderer& r, py::object frame_scene,
                                   py::object frame_settings) {
            const std::shared_ptr<Renderer> renderer = r.get();
            RenderStats s;
            RenderSettings settings = renderer->settings();
            if (!frame_settings.is_none()) settings = frame_settings.cast<RenderSettings>();
            const Scene* frame = frame_scene.is_none() ? nullptr : &frame_scene.cast<const Scene&>();
            {
                py::gil_scoped_release release;
                s = renderer->stats();
                if (frame) s.scene_hash = scene_hash_hex(*frame);
            }
            return farm_attributes(settings, s);
        }, py::arg("frame_scene") = py::none(), py::arg("frame_settings") = py::none(),
           "The EXR header attributes glslppm-merge reads: estimator, seed, settings, scene "
           "hash, pass ranges and passes. A tile's renderer (tile_render_inputs) is given the "
           "whole frame's scene and settings, whose camera and size the header names.")
        .def("write_passes_exr", [](PyRenderer& r, const std::string& path) {
            const std::shared_ptr<Renderer> renderer = r.get();
            py::gil_scoped_release release;
            const RenderSettings& settings = renderer->settings();
            write_multilayer_exr(path, settings.width, settings.height,
                                 render_pass_layers(renderer->film(), settings.passes,
                                                    renderer->render_passes(settings.passes),
                                                    renderer->light_groups(),
                                                    renderer->light_group_passes()),
                                 farm_attributes(settings, renderer->stats()));
        }, py::arg("path"),
           "Writes Combined, every enabled render pass and every light group's pass "
           "(Combined_<group>) as one multi-layer EXR with the farm "
           "attributes, as glslppm-render --passes-out does: a farm job's file for "
           "glslppm-merge.")
        .def("cancel", [](PyRenderer& r) { r.get()->cancel(); },
             "Stops a run in progress (on another thread) after its current pass.")
        .def("reset_film", [](PyRenderer& r) {
            py::gil_scoped_release release;
            r.get()->reset_film();
        }, "Starts the image again from no passes; scene, BVH and programs stay.")
        .def("set_camera", [](PyRenderer& r, const Camera& camera) {
            py::gil_scoped_release release;
            return r.get()->set_camera(camera);
        }, py::arg("camera"),
        "Looks through another camera and starts the image again, without a BVH build. "
        "False (nothing changed) when the camera needs other programs: make a new Renderer.")
        .def("update_tables", [](PyRenderer& r, const Scene& scene) {
            py::gil_scoped_release release;
            return r.get()->update_tables(scene);
        }, py::arg("scene"),
        "Takes the materials, lights, world and camera of a scene with the same geometry and "
        "starts the image again, without a BVH build. False (nothing changed) when they need "
        "other programs, images or geometry: make a new Renderer.")
        .def("_debug_set_photons_emitted", [](PyRenderer& r, std::uint64_t count) {
            py::gil_scoped_release release;
            r.get()->debug_set_photons_emitted(count);
        }, "Tests only: sets the 64-bit count of photon paths started.")
        .def("film", [](PyRenderer& r, std::optional<py::array> out, bool bottom_up) -> py::array {
            const std::shared_ptr<Renderer> renderer = r.get();
            const RenderSettings& s = renderer->settings();
            if (out) {
                // Into the caller's array: a viewport's redraws reuse one, writing no new pages.
                const bool fits = out->dtype().is(py::dtype::of<float>()) && out->ndim() == 3 &&
                                  out->shape(0) == s.height && out->shape(1) == s.width &&
                                  out->shape(2) == 4 && out->writeable() &&
                                  (out->flags() & py::array::c_style);
                if (!fits)
                    throw py::value_error("film(out): out must be a writable C-contiguous float32 "
                                          "array of shape (" + std::to_string(s.height) + ", " +
                                          std::to_string(s.width) + ", 4)");
                const std::span<float> pixels(static_cast<float*>(out->mutable_data()),
                                              static_cast<std::size_t>(out->size()));
                py::gil_scoped_release release;
                renderer->film_into(pixels, bottom_up);
                return *out;
            }
            if (bottom_up) {
                py::array_t<float> flipped({s.height, s.width, 4});
                const std::span<float> pixels(flipped.mutable_data(),
                                              static_cast<std::size_t>(flipped.size()));
                py::gil_scoped_release release;
                renderer->film_into(pixels, true);
                return std::move(flipped);
            }
            std::vector<float> film;
            {
                py::gil_scoped_release release;
                film = renderer->film();
            }
            return array_owning(std::move(film), {s.height, s.width, 4});
        }, py::arg("out") = py::none(), py::arg("bottom_up") = false,
        "Linear RGBA, height x width x 4 float32, row 0 at the top (bottom_up: at the bottom, "
        "as Blender's images store rows). out: an array of that shape to fill instead of a new "
        "one (returned).")
        .def("render_pass", [](PyRenderer& r, const std::string& name, bool bottom_up) {
            const py::dict images = render_pass_arrays(r, {name}, bottom_up);
            return py::object(images[py::str(name)]);
        }, py::arg("name"), py::arg("bottom_up") = false,
        "One of the settings' passes (docs/passes.md) as film() gives Combined: height x width "
        "x 1 (depth) or 3, the mean over the passes run; row 0 at the top (bottom_up: at the "
        "bottom, as Blender stores rows).")
        .def("light_group_passes", &light_group_arrays, py::arg("bottom_up") = false,
             "Every light group's pass (Scene.light_groups; docs/light_groups.md) as "
             "{name: height x width x 3}, as render_passes gives a pass: the light of the "
             "group's lights, emissive materials and world; with the light of no group they "
             "sum to film(). {} without groups.")
        .def("render_passes", &render_pass_arrays, py::arg("names"), py::arg("bottom_up") = false,
             "Several passes as render_pass() gives one, {name: array}, with one read back "
             "from the GPU.")
        .def_property_readonly("settings", [](PyRenderer& r) { return r.get()->settings(); },
                               "A copy of the settings the renderer was made with.")
        .def("photons", [](PyRenderer& r) {
            std::vector<float> photons;
            {
                py::gil_scoped_release release;
                photons = r.get()->photons();
            }
            const auto count = static_cast<py::ssize_t>(photons.size() / 12);
            return array_owning(std::move(photons), {count, 12});
        })
        .def("stats", [](PyRenderer& r) {
            RenderStats s;
            {
                py::gil_scoped_release release;
                s = r.get()->stats();
            }
            return stats_dict(s);
        })
        .def("close", [](PyRenderer& r) {
            py::gil_scoped_release release;
            r.close();
        }, "Frees the GL context and every GPU buffer now (also done on garbage collection).")
        .def_property_readonly("closed", [](const PyRenderer& r) { return r.closed(); })
        .def("_debug_close_on_native_thread", [](PyRenderer& r) {
            py::gil_scoped_release release;
            r.close_on_native_thread();
        }, "Tests only: close(), the last reference dropped on a thread that is not Python's.");
    // Tests only: a Scene's arrays released on a thread Python has never seen, as a copy of a
    // Scene freed inside a worker would release them.
    static std::unique_ptr<Scene> held_scene;
    m.def("_debug_hold_scene", [](const Scene& scene) {
        held_scene = std::make_unique<Scene>(scene);
    }, "Tests only: keeps a copy of the scene (sharing its arrays) in the module.");
    m.def("_debug_drop_held_scene_on_native_thread", [] {
        py::gil_scoped_release release;
        std::thread([owned = std::move(held_scene)]() mutable { owned.reset(); }).join();
    }, "Tests only: frees the kept copy on a new thread, the GIL released.");
    m.def("_debug_deferred_releases", [] {
        std::lock_guard lock(deferred_release::queue_mutex());
        return deferred_release::queue().size();
    }, "Tests only: references to Python objects freed off Python's thread, not yet released.");

    m.def("render_passes", [] {
        py::list passes;
        for (const RenderPassInfo& p : render_pass_catalog()) {
            py::dict d;
            d["name"] = p.name;
            d["blender"] = p.blender;
            d["blender_3x"] = render_pass_blender_3x(p.pass);
            d["channels"] = p.channels;
            d["channel_names"] = p.channel_names;
            d["light"] = p.light;
            passes.append(d);
        }
        return passes;
    }, "Every render pass beside Combined: its name, Blender's names (4.x, 3.x), channels, and "
       "whether it is part of Combined's light split (docs/passes.md).");
}

}  // namespace glslppm
