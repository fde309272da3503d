// EGL devices: which there are, what a render may allocate on each, and the GL objects
// glslppm holds (for leak tests).
#include <pybind11/stl.h>

#include "gl/device_limits.h"
#include "gl/egl_context.h"
#include "gl/object_counts.h"
#include "python/bindings.h"

namespace py = pybind11;

namespace glslppm {

void bind_devices(py::module_& m) {
    m.def("gl_object_counts", [] {
        const gl::GlObjectCounts c = gl::gl_object_counts();
        py::dict d;
        d["contexts"] = c.contexts;
        d["buffers"] = c.buffers;
        d["textures"] = c.textures;
        d["programs"] = c.programs;
        d["queries"] = c.queries;
        return d;
    }, "EGL contexts and GL objects glslppm created and has not deleted (process-wide).");
    m.def("device_limits", [](int device) {
        // What a render may allocate on a device, asked before allocating anything: the
        // largest storage buffer, and the GPU's memory where the driver says. Asked once
        // per device for the process (gl/device_limits.h).
        gl::DeviceLimits limits;
        {
            py::gil_scoped_release release;
            limits = gl::device_limits(device);
        }
        py::dict d;
        d["max_storage_buffer_bytes"] = limits.max_storage_buffer_bytes;
        d["memory_bytes"] = limits.memory_bytes;
        d["software"] = limits.software;
        d["renderer"] = limits.renderer;
        d["vendor"] = limits.vendor;
        return d;
    }, py::arg("device") = -1,
       "Limits of an EGL device: max_storage_buffer_bytes, memory_bytes (0: unknown), "
       "software, renderer, vendor.");
    m.def("list_devices", [] {
        py::list out;
        for (const auto& d : gl::list_devices()) out.append(py::str(d.name));
        return out;
    });
    m.def("describe_devices", [] {
        py::list out;
        for (const auto& d : gl::list_devices()) {
            py::dict e;
            e["index"] = d.index;
            e["name"] = d.name;
            e["software"] = d.software;
            out.append(e);
        }
        return out;
    }, "The EGL devices without opening them: index, name (DRM node, CUDA device or "
       "software) and whether it is a software renderer.");
}

}  // namespace glslppm
