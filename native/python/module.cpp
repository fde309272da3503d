// The pybind11 module `_glslppm`: scenes from numpy arrays (used in place where dtype and
// layout fit), renderers run in steps with the GIL released, films back as numpy arrays.
// Each bound type or group of functions has its own file (python/bindings.h); this one
// registers the exceptions and calls them in the order the types need.
#include <pybind11/pybind11.h>

#include "gl/gl_thread.h"
#include "gl/shader_program.h"
#include "python/bindings.h"
#include "render/renderer.h"

namespace py = pybind11;
using namespace glslppm;

PYBIND11_MODULE(_glslppm, m) {
    m.doc() = "glslppm: stochastic progressive photon mapping on the GPU through headless OpenGL";
    static py::exception<std::runtime_error> error(m, "GlslppmError", PyExc_RuntimeError);
    static py::exception<Cancelled> cancelled(m, "Cancelled", error.ptr());
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const Cancelled& e) {
            cancelled(e.what());
        } catch (const gl::GlError& e) {
            error(e.what());
        } catch (const gl::ShaderError& e) {
            error(e.what());
        }
    });
    // SceneError and std::invalid_argument become ValueError (pybind11's default).

    bind_materials(m);
    bind_scene(m);
    bind_settings(m);
    bind_renderer(m);
    bind_tiles(m);
    bind_files(m);
    bind_devices(m);
    bind_loaders(m);
    bind_motion(m);
}
