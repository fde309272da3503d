// The scene-file loaders: load_scene, load_texture, and scene_contents (a loaded scene
// as plain dicts and arrays).
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstring>

#include "image/image_file.h"
#include "loaders/scene_file.h"
#include "python/bindings.h"
#include "python/enum_names.h"

namespace py = pybind11;

namespace glslppm {
namespace {

template <typename T, typename Element>
py::array_t<T> array_of(std::span<const Element> items, std::size_t components) {
    py::array_t<T> out(
        {static_cast<py::ssize_t>(items.size()), static_cast<py::ssize_t>(components)});
    if (!items.empty())
        std::memcpy(out.mutable_data(), items.data(), items.size() * sizeof(Element));
    return out;
}

py::tuple vec3(glm::vec3 v) { return py::make_tuple(v.x, v.y, v.z); }

py::array_t<float> matrix(const float* column_major, int n) {
    py::array_t<float> out({n, n});
    for (int r = 0; r < n; ++r)
        for (int c = 0; c < n; ++c) out.mutable_at(r, c) = column_major[c * n + r];
    return out;
}

py::dict texture_dict(const Texture& t) {
    py::dict d;
    d["name"] = t.name;
    d["width"] = t.width;
    d["height"] = t.height;
    d["wrap"] = name_of(t.wrap, kTextureWraps);
    d["interpolation"] = name_of(t.interpolation, kTextureInterpolations);
    d["encoding"] = t.srgb8.empty() ? "linear" : "srgb8";
    const std::vector<py::ssize_t> shape{t.height, t.width, 4};
    if (!t.srgb8.empty()) {
        py::array_t<std::uint8_t> px(shape);
        std::memcpy(px.mutable_data(), t.srgb8.data(), t.srgb8.size());
        d["pixels"] = px;
    } else {
        py::array_t<float> px(shape);
        std::memcpy(px.mutable_data(), t.linear.data(), t.linear.size() * sizeof(float));
        d["pixels"] = px;
    }
    return d;
}

py::list materials_list(const Scene& s) {
    py::list out;
    for (const Material& m : s.materials) {
        py::dict d;
        d["kind"] = name_of(m.kind, kMaterialKinds);
        d["color"] = vec3(m.color);
        d["ior"] = m.ior;
        d["emission"] = vec3(m.emission);
        d["color_texture"] = m.color_texture;
        d["emission_two_sided"] = m.emission_two_sided;
        d["visible_to_camera"] = m.visible_to_camera;
        d["visible_in_reflections"] = m.visible_in_reflections;
        d["casts_shadow"] = m.casts_shadow;
        d["roughness"] = m.roughness;
        d["roughness_texture"] = m.roughness_texture;
        d["roughness_channel"] = name_of(m.roughness_channel, kTextureChannels);
        d["multiscatter"] = m.multiscatter;
        d["schlick"] = m.schlick;
        d["tint_reflection"] = m.tint_reflection;
        d["mix_a"] = m.mix_a;
        d["mix_b"] = m.mix_b;
        d["mix_factor"] = m.mix_factor;
        d["mix_texture"] = m.mix_texture;
        d["mix_channel"] = name_of(m.mix_channel, kTextureChannels);
        d["mix_mode"] = name_of(m.mix_mode, kMixModes);
        d["mix_ior"] = m.mix_ior;
        d["normal_texture"] = m.normal_texture;
        d["normal_strength"] = m.normal_strength;
        d["bump_texture"] = m.bump_texture;
        d["emission_texture"] = m.emission_texture;
        d["vertex_color"] = m.vertex_color;
        d["absorption"] = vec3(m.absorption);
        out.append(d);
    }
    return out;
}

py::list lights_list(const Scene& s) {
    py::list out;
    for (const Light& l : s.lights) {
        py::dict d;
        d["kind"] = name_of(l.kind, kLightKinds);
        d["color"] = vec3(l.color);
        d["power"] = l.power;
        d["position"] = vec3(l.position);
        d["direction"] = vec3(l.direction);
        d["spot_size"] = l.spot_size;
        d["spot_blend"] = l.spot_blend;
        d["radius"] = l.radius;
        d["facing_disc"] = l.facing_disc;
        d["angle"] = l.angle;
        out.append(d);
    }
    return out;
}

py::dict camera_dict(const Camera& c) {
    py::dict d;
    d["to_world"] = matrix(&c.to_world[0][0], 4);
    d["fov_x"] = c.fov_x;
    d["projection"] = c.projection == Projection::Perspective ? "perspective" : "orthographic";
    d["ortho_scale"] = c.ortho_scale;
    return d;
}

// Everything in a Scene as plain Python values (arrays are copies), for tests and scripts.
py::dict scene_contents(const Scene& s) {
    py::dict d;
    d["positions"] = array_of<float>(s.mesh.positions, 3);
    d["triangles"] = array_of<std::uint32_t>(s.mesh.triangles, 3);
    d["normals"] = array_of<float>(s.mesh.normals, 3);
    d["uvs"] = array_of<float>(s.mesh.uvs, 2);
    d["tangents"] = array_of<float>(s.mesh.tangents, 4);
    d["colors"] = array_of<float>(s.mesh.colors, 3);
    py::array_t<std::uint32_t> ids(static_cast<py::ssize_t>(s.mesh.material_ids.size()));
    if (!s.mesh.material_ids.empty())
        std::memcpy(ids.mutable_data(), s.mesh.material_ids.data(), s.mesh.material_ids.size() * 4);
    d["material_ids"] = ids;
    d["materials"] = materials_list(s);
    d["lights"] = lights_list(s);
    d["camera"] = camera_dict(s.camera);
    py::list textures;
    for (const Texture& t : s.textures) textures.append(texture_dict(t));
    d["textures"] = textures;
    d["environment"] = vec3(s.environment);
    d["environment_texture"] = s.environment_texture;
    d["environment_to_world"] = matrix(&s.environment_to_world[0][0], 3);
    return d;
}

}  // namespace

void bind_loaders(py::module_& m) {
    m.def(
        "load_scene",
        [](const std::string& path, float aspect, const std::string& mtl_convention) {
            SceneFileOptions options;
            options.mtl = parse_mtl_convention(mtl_convention);
            LoadedScene loaded;
            {
                py::gil_scoped_release release;
                loaded = load_scene_file(path, aspect, options);
            }
            return py::make_tuple(std::move(loaded.scene), loaded.warnings);
        },
        py::arg("path"), py::arg("aspect") = 1.0f, py::arg("mtl_convention") = "standard",
        "Loads a .gltf, .glb or .obj file: (Scene, warnings). aspect = width / "
        "height of the render (glTF cameras give a vertical angle). mtl_convention: "
        "'standard' (the MTL specification) or 'glslppm2015' (the original glslppm's scene "
        "files: Ka a light, Ks 1 with Ns 100 a mirror, 'glass*' a glass). Bad files raise "
        "ValueError naming the file and the element.");
    m.def(
        "load_texture",
        [](const std::string& path) {
            Texture t;
            {
                py::gil_scoped_release release;
                t = load_texture(path);
            }
            return texture_dict(t);
        },
        py::arg("path"),
        "Reads a PNG, JPEG, .hdr or .exr image as the renderer stores it "
        "(rows bottom-first): a dict with width, height, encoding, pixels.");
    m.def("scene_contents", &scene_contents, py::arg("scene"),
          "Copies a Scene's arrays, materials, lights, camera and textures into a dict.");
}

}  // namespace glslppm
