// numpy arrays across the module's seam: films handed to Python without a copy, input
// arrays checked and used in place, and the owner that keeps a Scene's arrays alive and lets
// go of them safely on threads Python never saw (docs/threads.md).
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <mutex>
#include <set>
#include <string>
#include <vector>

namespace glslppm {

namespace py = pybind11;

// A numpy array over the vector's own memory (moved, not copied): a film of 1920 x 1080 is
// 33 MB, which a copy would add to every progressive update.
py::array_t<float> array_owning(std::vector<float>&& values, std::vector<py::ssize_t> shape);

// References to Python objects let go of where this thread may not hold the GIL. A
// Renderer is freed by whichever thread drops it last: a worker thread whose run() outlived
// close(), or a binding that released the GIL. Waiting for the GIL inside a destructor
// can deadlock (the GIL's holder may be waiting for this very thread), so such references
// are queued and released under the GIL: by a pending call, which Python runs on its main
// thread at its next bytecode, or by the next Scene made here, whichever comes first.
namespace deferred_release {

std::mutex& queue_mutex();
std::vector<PyObject*>& queue();
// GIL held.
void drain();
// Any thread, GIL or not: takes over the references (objects are left empty).
void hand_over(std::vector<py::object>& objects);

}  // namespace deferred_release

// Holds the numpy arrays a Scene's MeshView points into.
// Registered while alive, so that a Scene's keepalive can be recognised as one (scenes from
// the loaders and procedural scenes keep an OwnedMesh instead).
struct ArrayOwner {
    std::vector<py::object> arrays;
    ArrayOwner() {
        std::lock_guard lock(registry_mutex());
        registry().insert(this);
    }
    ~ArrayOwner() {
        {
            std::lock_guard lock(registry_mutex());
            registry().erase(this);
        }
        if (!Py_IsInitialized()) {
            // Python has gone (a renderer freed at exit): the arrays went with it.
            for (py::object& array : arrays) array.release();
        } else if (PyGILState_Check()) {
            arrays.clear();
        } else {
            deferred_release::hand_over(arrays);
        }
    }
    static bool is_one(const void* p) {
        std::lock_guard lock(registry_mutex());
        return registry().count(static_cast<const ArrayOwner*>(p)) != 0;
    }
    static std::mutex& registry_mutex() {
        static std::mutex m;
        return m;
    }
    static std::set<const ArrayOwner*>& registry() {
        static std::set<const ArrayOwner*> r;
        return r;
    }
};

// "dtype float32, shape (3, 4)", for error messages.
std::string describe(const py::array& a);

// Checks dtype and shape and returns a C-contiguous view: the array itself when it already
// fits (no copy), else a contiguous copy of the right dtype only if the dtype is right.
template <class T>
py::array_t<T> take_array(const py::object& object, const char* name, py::ssize_t columns,
                          const char* dtype_name) {
    if (!py::isinstance<py::array>(object))
        throw py::value_error(std::string(name) + ": expected a numpy array of " + dtype_name);
    py::array a = py::reinterpret_borrow<py::array>(object);
    if (!a.dtype().is(py::dtype::of<T>()))
        throw py::value_error(std::string(name) + ": expected dtype " + dtype_name + ", got " +
                              describe(a));
    const bool shape_ok = columns == 0 ? a.ndim() == 1
                                       : (a.ndim() == 2 && a.shape(1) == columns);
    if (!shape_ok) {
        const std::string want = columns == 0 ? "(N,)" : "(N, " + std::to_string(columns) + ")";
        throw py::value_error(std::string(name) + ": expected shape " + want + ", got " +
                              describe(a));
    }
    return py::array_t<T, py::array::c_style>::ensure(a);
}

}  // namespace glslppm
