// The module `_glslppm` is bound in parts, one file per bound type or group of functions;
// module.cpp registers its exceptions and calls each part in the order the types need.
#pragma once

#include <pybind11/pybind11.h>

namespace glslppm {

struct RenderStats;

void bind_materials(pybind11::module_& m);  // Material, Texture: material_bindings.cpp
void bind_scene(pybind11::module_& m);      // Light, Camera, Scene, procedural scenes: scene_bindings.cpp
void bind_settings(pybind11::module_& m);   // Settings, pppm_pass_radius: settings_bindings.cpp
void bind_renderer(pybind11::module_& m);   // CancelFlag, Renderer, render_passes: renderer_bindings.cpp
void bind_tiles(pybind11::module_& m);      // plan_tiles, tile_render_inputs, render_tiled: tile_bindings.cpp
void bind_files(pybind11::module_& m);      // EXR files, film and farm merges: file_bindings.cpp
void bind_devices(pybind11::module_& m);    // EGL devices, their limits, GL objects: device_bindings.cpp
void bind_loaders(pybind11::module_& m);    // load_scene, load_texture, scene_contents: loader_bindings.cpp
void bind_motion(pybind11::module_& m);     // Scene.set_motion, shutter_sample: motion_bindings.cpp

// A render's statistics as a dict (Renderer.stats() and render_tiled's): renderer_bindings.cpp.
pybind11::dict stats_dict(const RenderStats& s);

}  // namespace glslppm
