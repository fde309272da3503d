// Motion blur (render/motion.h): Scene.set_motion, the shutter's sample per pass and the
// interpolation of transforms between steps, for the add-on and the tests.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "python/bindings.h"
#include "render/motion.h"

namespace py = pybind11;

namespace glslppm {
namespace {

using Matrices = py::array_t<float, py::array::c_style | py::array::forcecast>;

// (N, 4, 4) row-major matrices (Blender's matrix_world), as the instances take them.
std::vector<glm::mat4> matrices_of(const Matrices& a, const std::string& name) {
    if (a.ndim() != 3 || a.shape(1) != 4 || a.shape(2) != 4)
        throw py::value_error(name + ": expected an array of shape (N, 4, 4)");
    std::vector<glm::mat4> out(static_cast<std::size_t>(a.shape(0)));
    for (std::size_t n = 0; n < out.size(); ++n)
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) out[n][c][r] = a.at(py::ssize_t(n), r, c);
    return out;
}

py::array_t<float> array_of(const glm::mat4& m) {
    py::array_t<float> a({4, 4});
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) a.mutable_at(r, c) = m[c][r];
    return a;
}

using Vertices = py::array_t<float, py::array::c_style | py::array::forcecast>;

// (S, V, 3) per-step vertex arrays, or None: empty.
std::vector<std::vector<glm::vec3>> vertex_steps(const py::object& o, const std::string& name) {
    std::vector<std::vector<glm::vec3>> out;
    if (o.is_none()) return out;
    const Vertices a = Vertices::ensure(o);
    if (!a || a.ndim() != 3 || a.shape(2) != 3)
        throw py::value_error(name + ": expected an array of shape (steps, vertices, 3)");
    out.resize(static_cast<std::size_t>(a.shape(0)));
    for (std::size_t k = 0; k < out.size(); ++k) {
        out[k].resize(static_cast<std::size_t>(a.shape(1)));
        for (std::size_t v = 0; v < out[k].size(); ++v)
            out[k][v] = glm::vec3(a.at(py::ssize_t(k), py::ssize_t(v), 0),
                                  a.at(py::ssize_t(k), py::ssize_t(v), 1),
                                  a.at(py::ssize_t(k), py::ssize_t(v), 2));
    }
    return out;
}

using MeshSteps = std::tuple<std::uint32_t, std::vector<float>, py::object, py::object>;

TransformSteps steps_of(const std::vector<float>& times, const Matrices& matrices,
                        const std::string& name) {
    TransformSteps s;
    s.times = times;
    s.to_world = matrices_of(matrices, name);
    return s;
}

void set_motion(Scene& scene, float shutter_open, float shutter_length,
                const std::vector<std::tuple<std::uint32_t, std::vector<float>, Matrices>>& instances,
                const std::vector<float>& camera_times, const py::object& camera_to_world,
                const std::vector<float>& camera_fov_x, const std::vector<float>& shutter_curve,
                const std::vector<MeshSteps>& meshes,
                const std::vector<std::tuple<std::uint32_t, std::vector<float>, Matrices>>& lights) {
    SceneMotion m;
    m.shutter_open = shutter_open;
    m.shutter_length = shutter_length;
    m.shutter_curve = shutter_curve;
    for (std::size_t k = 0; k < instances.size(); ++k) {
        const auto& [index, times, matrices] = instances[k];
        m.instances.push_back(InstanceMotion{
            index, steps_of(times, matrices, "motion.instances[" + std::to_string(k) + "]")});
    }
    if (!camera_times.empty() || !camera_to_world.is_none()) {
        if (camera_to_world.is_none())
            throw py::value_error("motion.camera: camera_times need camera_to_world");
        m.camera = steps_of(camera_times, Matrices::ensure(camera_to_world), "motion.camera");
    }
    m.camera_fov_x = camera_fov_x;
    for (std::size_t k = 0; k < meshes.size(); ++k) {
        const auto& [mesh, times, positions, normals] = meshes[k];
        const std::string name = "motion.meshes[" + std::to_string(k) + "]";
        m.meshes.push_back(MeshDeformation{mesh, times, vertex_steps(positions, name + ".positions"),
                                           vertex_steps(normals, name + ".normals")});
    }
    for (std::size_t k = 0; k < lights.size(); ++k) {
        const auto& [index, times, matrices] = lights[k];
        m.lights.push_back(LightMotion{
            index, steps_of(times, matrices, "motion.lights[" + std::to_string(k) + "]")});
    }
    Scene checked = scene;  // validated before it replaces the scene's motion
    checked.motion = m;
    validate_motion(checked);
    scene.motion = std::move(m);
}

}  // namespace

void bind_motion(py::module_& m) {
    auto scene = py::reinterpret_borrow<py::class_<Scene>>(m.attr("Scene"));
    scene.def("set_motion", &set_motion, py::arg("shutter_open") = 0.0f,
              py::arg("shutter_length") = 0.0f,
              py::arg("instances") =
                  std::vector<std::tuple<std::uint32_t, std::vector<float>, Matrices>>{},
              py::arg("camera_times") = std::vector<float>{},
              py::arg("camera_to_world") = py::none(),
              py::arg("camera_fov_x") = std::vector<float>{},
              py::arg("shutter_curve") = std::vector<float>{},
              py::arg("meshes") = std::vector<MeshSteps>{},
              py::arg("lights") =
                  std::vector<std::tuple<std::uint32_t, std::vector<float>, Matrices>>{},
              "Motion blur: the shutter (open time and length in frames, relative to the "
              "frame; shutter_curve: its openness at evenly spaced points from opening to "
              "closing, empty for a box), instances' transforms at steps ([(instance, times, (N, 4, 4) matrices)]) "
              "and the camera's (camera_fov_x: one per step, or empty), and instance meshes' "
              "deformation ([(mesh, times, (S, V, 3) positions, (S, V, 3) normals or None)]), "
              "and point, spot and sun lights' transforms at steps ([(light, times, (N, 4, 4) "
              "matrices)]: the light at each matrix's origin, shining along its -Z). "
              "Validated here "
              "(ValueError naming the problem). docs/motion_blur.md.")
        .def_property_readonly("has_motion", [](const Scene& s) { return !s.motion.empty(); });
    m.def("shutter_sample", &shutter_sample, py::arg("seed"), py::arg("pass_index"),
          "Where in the shutter, in [0, 1), pass `pass_index` renders: the radical inverse of "
          "the index rotated by an offset from the seed.");
    m.def("shutter_position",
          [](const std::vector<float>& curve, double u) {
              Scene probe;
              probe.motion.shutter_length = 1.0f;
              probe.motion.shutter_curve = curve;
              probe.motion.camera.times = {0.0f};
              probe.motion.camera.to_world = {glm::mat4(1.0f)};
              validate_motion(probe);
              return curve.empty() ? u : ShutterCurve(curve).position(u);
          },
          py::arg("curve"), py::arg("u"),
          "Where in the shutter, in [0, 1], a sample u of [0, 1) lands under the shutter "
          "curve (its inverse cumulative distribution; u itself for an empty curve).");
    m.def("interpolate_transform",
          [](const std::vector<float>& times, const Matrices& matrices, double t) {
              const TransformSteps s = steps_of(times, matrices, "matrices");
              Scene probe;
              probe.instances.resize(1);
              probe.motion.shutter_length = 1.0f;
              probe.motion.instances.push_back(InstanceMotion{0, s});
              validate_motion(probe);
              return array_of(TransformMotion(s).at(t));
          },
          py::arg("times"), py::arg("matrices"), py::arg("t"),
          "The transform at time t between steps (rotation by quaternion slerp, translation "
          "and stretch linearly, as Cycles interpolates), row-major 4x4.");
}

}  // namespace glslppm
