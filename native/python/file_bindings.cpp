// Files: float EXR images in and out, PPPM films and farm renders merged.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "image/exr.h"
#include "python/bindings.h"
#include "render/farm_merge.h"
#include "render/film_merge.h"

namespace py = pybind11;

namespace glslppm {

void bind_files(py::module_& m) {
    m.def("read_exr", [](const std::string& path) {
        std::map<std::string, std::string> attributes;
        FloatImage image;
        {
            py::gil_scoped_release release;
            image = read_exr(path, &attributes);
        }
        py::array_t<float> out({image.height, image.width, 4});
        std::memcpy(out.mutable_data(), image.rgba.data(), image.rgba.size() * sizeof(float));
        return py::make_tuple(out, attributes);
    }, py::arg("path"), "Reads a float RGBA EXR: (H x W x 4 array, glslppm header attributes).");

    m.def("read_exr_channels", [](const std::string& path) {
        int width = 0, height = 0;
        std::map<std::string, std::vector<float>> channels;
        {
            py::gil_scoped_release release;
            channels = read_exr_channels(path, &width, &height);
        }
        py::dict out;
        for (const auto& [name, data] : channels) {
            py::array_t<float> a({height, width});
            std::memcpy(a.mutable_data(), data.data(), data.size() * sizeof(float));
            out[py::str(name)] = a;
        }
        return out;
    }, py::arg("path"), "Every channel of an EXR file by its full name ('ViewLayer.Depth.Z'), "
       "each height x width.");
    m.def("write_exr", [](const std::string& path, py::array_t<float, py::array::c_style | py::array::forcecast> rgba,
                          std::map<std::string, std::string> attributes) {
        if (rgba.ndim() != 3 || rgba.shape(2) != 4)
            throw py::value_error("rgba: expected shape (H, W, 4)");
        FloatImage image{static_cast<int>(rgba.shape(1)), static_cast<int>(rgba.shape(0)),
                         std::vector<float>(rgba.data(), rgba.data() + rgba.size())};
        py::gil_scoped_release release;
        write_exr(path, image, attributes);
    }, py::arg("path"), py::arg("rgba"), py::arg("attributes") = std::map<std::string, std::string>{});

    m.def("merge_films", [](const std::vector<py::array_t<float, py::array::c_style | py::array::forcecast>>& films,
                            const std::vector<std::uint64_t>& passes) {
        if (films.empty()) throw py::value_error("films: at least one is needed");
        std::vector<std::vector<float>> copies;
        for (const auto& f : films) copies.emplace_back(f.data(), f.data() + f.size());
        std::vector<const std::vector<float>*> views;
        for (const auto& c : copies) views.push_back(&c);
        const std::vector<float> merged = merge_films(views, passes);
        py::array_t<float> out(films[0].request().shape);
        std::memcpy(out.mutable_data(), merged.data(), merged.size() * sizeof(float));
        return out;
    }, py::arg("films"), py::arg("passes"),
       "PPPM films, each the mean of its own passes, merged: sum passes[k] films[k] / sum passes.");
    m.def("merge_farm_files", [](const std::vector<std::string>& paths, const std::string& out) {
        try {
            py::gil_scoped_release release;
            return merge_farm_files(paths, out);
        } catch (const FarmMergeError& e) {
            throw py::value_error(e.what());
        }
    }, py::arg("paths"), py::arg("out"),
       "glslppm-merge: merges PPPM renders of disjoint pass sets into out; ValueError naming "
       "the file and field when they do not belong together. Returns out's attributes.");
}

}  // namespace glslppm
