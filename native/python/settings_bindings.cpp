// Settings: every keyword's default is RenderSettings' own, and every field reads back, so
// that the add-on's defaults can be checked against the module's.
#include <pybind11/stl.h>

#include <algorithm>

#include "python/bindings.h"
#include "render/pppm_schedule.h"
#include "render/render_passes.h"
#include "render/settings.h"
#include "render/specializations.h"

namespace py = pybind11;

namespace glslppm {

void bind_settings(py::module_& m) {
    // The keyword defaults are RenderSettings' own (native/render/settings.h).
    const RenderSettings defaults;
    py::class_<RenderSettings>(m, "Settings")
        .def(py::init([](int width, int height, std::uint32_t photons_per_pass, float alpha,
                         float initial_radius, float radius_scale, int max_bounces,
                         const std::string& hash,
                         const std::string& rng, int device, std::uint64_t seed, int leaf_size,
                         bool profile, bool full_variant, int max_texture_size,
                         bool transparent, bool transparent_glass,
                         const std::string& direct_light, float glossy_threshold,
                         const std::string& estimator, std::vector<int> devices,
                         std::uint64_t first_pass, const std::string& instancing,
                         std::uint64_t max_block_bytes, std::vector<std::string> passes,
                         const std::string& bump_shadowing, int max_diffuse_bounces,
                         int max_glossy_bounces, int max_transmission_bounces,
                         bool light_tracing, bool photon_warm_up,
                         const std::string& vcm_techniques, float emitter_mis_fraction) {
                 RenderSettings s;
                 s.width = width;
                 s.height = height;
                 s.photons_per_pass = photons_per_pass;
                 s.alpha = alpha;
                 s.initial_radius = initial_radius;
                 s.radius_scale = radius_scale;
                 s.max_bounces = max_bounces;
                 s.max_diffuse_bounces = max_diffuse_bounces;
                 s.max_glossy_bounces = max_glossy_bounces;
                 s.max_transmission_bounces = max_transmission_bounces;
                 s.hash = parse_hash_mode(hash);
                 s.rng = parse_rng_kind(rng);
                 s.direct_light = parse_direct_light(direct_light);
                 s.device = device;
                 s.seed = seed;
                 s.leaf_size = leaf_size;
                 s.profile = profile;
                 s.full_variant = full_variant;
                 s.max_texture_size = max_texture_size;
                 s.transparent = transparent;
                 s.transparent_glass = transparent_glass;
                 s.glossy_threshold = glossy_threshold;
                 s.emitter_mis_fraction = emitter_mis_fraction;
                 s.estimator = parse_estimator(estimator);
                 s.devices = std::move(devices);
                 s.first_pass = first_pass;
                 s.instancing = parse_instancing(instancing);
                 s.max_block_bytes = max_block_bytes;
                 s.bump_shadowing = parse_bump_shadowing(bump_shadowing);
                 s.light_tracing = light_tracing;
                 s.photon_warm_up = photon_warm_up;
                 s.vcm_techniques = parse_vcm_techniques(vcm_techniques);
                 for (const std::string& name : passes) {
                     for (RenderPass p : parse_render_pass_list(name))
                         if (std::find(s.passes.begin(), s.passes.end(), p) == s.passes.end())
                             s.passes.push_back(p);
                 }
                 validate(s);
                 return s;
             }),
             py::arg("width") = defaults.width, py::arg("height") = defaults.height,
             py::arg("photons_per_pass") = defaults.photons_per_pass,
             py::arg("alpha") = defaults.alpha, py::arg("initial_radius") = defaults.initial_radius,
             py::arg("radius_scale") = defaults.radius_scale,
             py::arg("max_bounces") = defaults.max_bounces, py::arg("hash") = to_string(defaults.hash),
             py::arg("rng") = to_string(defaults.rng), py::arg("device") = defaults.device,
             py::arg("seed") = defaults.seed, py::arg("leaf_size") = defaults.leaf_size,
             py::arg("profile") = defaults.profile, py::arg("full_variant") = defaults.full_variant,
             py::arg("max_texture_size") = defaults.max_texture_size,
             py::arg("transparent") = defaults.transparent,
             py::arg("transparent_glass") = defaults.transparent_glass,
             py::arg("direct_light") = to_string(defaults.direct_light),
             py::arg("glossy_threshold") = defaults.glossy_threshold,
             py::arg("estimator") = to_string(defaults.estimator),
             py::arg("devices") = defaults.devices, py::arg("first_pass") = defaults.first_pass,
             py::arg("instancing") = to_string(defaults.instancing),
             py::arg("max_block_bytes") = defaults.max_block_bytes,
             py::arg("passes") = std::vector<std::string>{},
             py::arg("bump_shadowing") = to_string(defaults.bump_shadowing),
             py::arg("max_diffuse_bounces") = defaults.max_diffuse_bounces,
             py::arg("max_glossy_bounces") = defaults.max_glossy_bounces,
             py::arg("max_transmission_bounces") = defaults.max_transmission_bounces,
             py::arg("light_tracing") = defaults.light_tracing,
             py::arg("photon_warm_up") = defaults.photon_warm_up,
             py::arg("vcm_techniques") = to_string(defaults.vcm_techniques),
             py::arg("emitter_mis_fraction") = defaults.emitter_mis_fraction)
        .def_readonly("width", &RenderSettings::width)
        .def_readonly("max_bounces", &RenderSettings::max_bounces)
        .def_readonly("max_diffuse_bounces", &RenderSettings::max_diffuse_bounces)
        .def_readonly("max_glossy_bounces", &RenderSettings::max_glossy_bounces)
        .def_readonly("max_transmission_bounces", &RenderSettings::max_transmission_bounces)
        .def_readonly("max_block_bytes", &RenderSettings::max_block_bytes)
        .def_readonly("height", &RenderSettings::height)
        .def_readonly("radius_scale", &RenderSettings::radius_scale)
        .def_property_readonly("estimator", [](const RenderSettings& s) { return to_string(s.estimator); })
        .def_readonly("devices", &RenderSettings::devices)
        .def_readonly("first_pass", &RenderSettings::first_pass)
        // Every other setting readable too, so that callers (the add-on's defaults test)
        // can compare theirs with the module's.
        .def_readonly("photons_per_pass", &RenderSettings::photons_per_pass)
        .def_readonly("alpha", &RenderSettings::alpha)
        .def_readonly("initial_radius", &RenderSettings::initial_radius)
        .def_readonly("device", &RenderSettings::device)
        .def_readonly("seed", &RenderSettings::seed)
        .def_readonly("leaf_size", &RenderSettings::leaf_size)
        .def_readonly("max_texture_size", &RenderSettings::max_texture_size)
        .def_readonly("transparent", &RenderSettings::transparent)
        .def_readonly("transparent_glass", &RenderSettings::transparent_glass)
        .def_readonly("glossy_threshold", &RenderSettings::glossy_threshold)
        .def_readonly("emitter_mis_fraction", &RenderSettings::emitter_mis_fraction)
        .def_readonly("light_tracing", &RenderSettings::light_tracing)
        .def_readonly("photon_warm_up", &RenderSettings::photon_warm_up)
        .def_property_readonly("vcm_techniques",
                               [](const RenderSettings& s) { return to_string(s.vcm_techniques); })
        .def_property_readonly("hash", [](const RenderSettings& s) { return to_string(s.hash); })
        .def_property_readonly("rng", [](const RenderSettings& s) { return to_string(s.rng); })
        .def_property_readonly("direct_light",
                               [](const RenderSettings& s) { return to_string(s.direct_light); })
        .def_property_readonly("instancing",
                               [](const RenderSettings& s) { return to_string(s.instancing); })
        .def_property_readonly("bump_shadowing",
                               [](const RenderSettings& s) { return to_string(s.bump_shadowing); })
        .def_property_readonly("passes", [](const RenderSettings& s) {
            std::vector<std::string> names;
            for (RenderPass p : s.passes) names.push_back(render_pass_info(p).name);
            return names;
        }, "The render passes beside Combined, by name (docs/passes.md).");
    m.def("pppm_pass_radius", &pppm_pass_radius, py::arg("initial_radius"), py::arg("floor"),
          py::arg("pass_index"), py::arg("alpha"),
          "PPPM's radius of a pass: initial_radius s(i), never below floor.");
    m.def("specializations", [] {
        py::list rows;
        for (const Specialization& row : specializations()) {
            py::dict d;
            d["name"] = row.name;
            d["define"] = row.define;
            d["needs"] = row.needs;
            d["gain"] = row.gain;
            d["in_full_variant"] = row.in_full_variant;
            rows.append(d);
        }
        return rows;
    }, "The programs' compile-time specializations, one row each (native/render/"
       "specializations.h): name, define, what a scene needs for it, its measured gain, and "
       "whether the full variant compiles it.");
}

}  // namespace glslppm
