#include "python/numpy_arrays.h"

namespace glslppm {

py::array_t<float> array_owning(std::vector<float>&& values, std::vector<py::ssize_t> shape) {
    auto* owned = new std::vector<float>(std::move(values));
    const py::capsule base(owned, [](void* p) { delete static_cast<std::vector<float>*>(p); });
    return py::array_t<float>(shape, owned->data(), base);
}

namespace deferred_release {

std::mutex& queue_mutex() {
    static std::mutex m;
    return m;
}
std::vector<PyObject*>& queue() {
    static std::vector<PyObject*> q;
    return q;
}

void drain() {
    std::vector<PyObject*> objects;
    {
        std::lock_guard lock(queue_mutex());
        objects.swap(queue());
    }
    for (PyObject* object : objects) Py_DECREF(object);
}

namespace {

int pending_call(void*) {
    drain();
    return 0;
}

}  // namespace

void hand_over(std::vector<py::object>& objects) {
    bool schedule = false;
    {
        std::lock_guard lock(queue_mutex());
        schedule = queue().empty();
        for (py::object& object : objects)
            if (object) queue().push_back(object.release().ptr());
    }
    objects.clear();  // empty handles now: no reference count is touched
    // Needs neither the GIL nor a thread state (Python's C API documentation).
    if (schedule) Py_AddPendingCall(pending_call, nullptr);
}

}  // namespace deferred_release

std::string describe(const py::array& a) {
    std::string shape = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i)
        shape += (i ? ", " : "") + std::to_string(a.shape(i));
    shape += a.ndim() == 1 ? ",)" : ")";
    return "dtype " + std::string(py::str(a.dtype())) + ", shape " + shape;
}

}  // namespace glslppm
