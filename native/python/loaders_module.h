// The scene-file loaders in the Python module: load_scene, load_texture, scene_contents.
#pragma once

#include <pybind11/pybind11.h>

namespace glslppm {

// Registers the loader functions on the module (called from PYBIND11_MODULE, after Scene).
void bind_loaders(pybind11::module_& m);

}  // namespace glslppm
