// Material and Texture: a material's kind, lobes' inputs and textures by index, and images
// from numpy arrays (sRGB bytes or linear floats).
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <array>
#include <optional>

#include "python/bindings.h"
#include "python/enum_names.h"
#include "python/numpy_arrays.h"
#include "scene/scene.h"

namespace glslppm {
namespace {

Material make_material(const std::string& kind, std::array<float, 3> color, float ior,
                       std::array<float, 3> emission, int color_texture,
                       bool emission_two_sided, bool visible_to_camera, bool casts_shadow,
                       float roughness, int roughness_texture,
                       const std::string& roughness_channel, bool multiscatter, bool schlick,
                       bool tint_reflection, int mix_a, int mix_b, float mix_factor,
                       int mix_texture, const std::string& mix_channel,
                       const std::string& mix_mode, float mix_ior, int normal_texture,
                       float normal_strength, int bump_texture, float bump_strength,
                       float bump_distance, int emission_texture,
                       std::array<float, 3> f82_tint, bool visible_in_reflections,
                       bool vertex_color, std::array<float, 3> absorption) {
    Material m;
    m.kind = parse_name<MaterialKind>(kind, kMaterialKinds, "Material kind");
    m.color = {color[0], color[1], color[2]};
    m.ior = ior;
    m.emission = {emission[0], emission[1], emission[2]};
    m.color_texture = color_texture;
    m.emission_two_sided = emission_two_sided;
    m.visible_to_camera = visible_to_camera;
    m.casts_shadow = casts_shadow;
    m.visible_in_reflections = visible_in_reflections;
    m.roughness = roughness;
    m.roughness_texture = roughness_texture;
    m.roughness_channel = parse_name<TextureChannel>(roughness_channel, kTextureChannels,
                                                     "Material roughness_channel");
    m.multiscatter = multiscatter;
    m.schlick = schlick;
    m.tint_reflection = tint_reflection;
    m.mix_a = mix_a;
    m.mix_b = mix_b;
    m.mix_factor = mix_factor;
    m.mix_texture = mix_texture;
    m.mix_channel = parse_name<TextureChannel>(mix_channel, kTextureChannels,
                                               "Material mix_channel");
    m.normal_texture = normal_texture;
    m.normal_strength = normal_strength;
    m.bump_texture = bump_texture;
    m.bump_strength = bump_strength;
    m.bump_distance = bump_distance;
    m.emission_texture = emission_texture;
    m.f82_tint = {f82_tint[0], f82_tint[1], f82_tint[2]};
    m.absorption = {absorption[0], absorption[1], absorption[2]};
    m.mix_mode = parse_name<MixFactor>(mix_mode, kMixModes, "Material mix_mode");
    m.mix_ior = mix_ior;
    m.vertex_color = vertex_color;
    return m;
}

// An image from a (height, width, 4) uint8 (sRGB) or float32 (linear) array, row 0 at the
// bottom as in Blender's pixels.
Texture make_texture(const py::array& pixels, const std::string& wrap, const std::string& name,
                     std::array<std::array<float, 3>, 2> uv_map,
                     std::optional<std::array<std::array<float, 4>, 2>> position_map,
                     const std::string& interpolation) {
    Texture t;
    t.uv_map_u = {uv_map[0][0], uv_map[0][1], uv_map[0][2]};
    t.uv_map_v = {uv_map[1][0], uv_map[1][1], uv_map[1][2]};
    if (position_map) {
        const auto& m = *position_map;
        t.from_position = true;
        t.position_map_u = {m[0][0], m[0][1], m[0][2], m[0][3]};
        t.position_map_v = {m[1][0], m[1][1], m[1][2], m[1][3]};
    }
    t.name = name;
    if (pixels.ndim() != 3 || pixels.shape(2) != 4)
        throw py::value_error("Texture '" + name + "' pixels: expected shape (height, width, 4), "
                              "got " + describe(pixels));
    t.height = static_cast<int>(pixels.shape(0));
    t.width = static_cast<int>(pixels.shape(1));
    if (pixels.dtype().is(py::dtype::of<std::uint8_t>())) {
        auto a = py::array_t<std::uint8_t, py::array::c_style>::ensure(pixels);
        t.srgb8.assign(a.data(), a.data() + a.size());
    } else if (pixels.dtype().is(py::dtype::of<float>())) {
        auto a = py::array_t<float, py::array::c_style>::ensure(pixels);
        t.linear.assign(a.data(), a.data() + a.size());
    } else {
        throw py::value_error("Texture '" + name + "' pixels: expected uint8 (sRGB) or float32 "
                              "(linear), got " + describe(pixels));
    }
    t.wrap = parse_name<TextureWrap>(wrap, kTextureWraps, "Texture wrap");
    t.interpolation = parse_name<TextureInterpolation>(
        interpolation, kTextureInterpolations, ("Texture '" + name + "' interpolation").c_str());
    return t;
}

}  // namespace

void bind_materials(py::module_& m) {
    py::class_<Material>(m, "Material")
        .def(py::init(&make_material), py::arg("kind") = "diffuse",
             py::arg("color") = std::array<float, 3>{0.8f, 0.8f, 0.8f}, py::arg("ior") = 1.5f,
             py::arg("emission") = std::array<float, 3>{0.0f, 0.0f, 0.0f},
             py::arg("color_texture") = -1, py::arg("emission_two_sided") = true,
             py::arg("visible_to_camera") = true, py::arg("casts_shadow") = true,
             py::arg("roughness") = 0.0f, py::arg("roughness_texture") = -1,
             py::arg("roughness_channel") = "luminance", py::arg("multiscatter") = true,
             py::arg("schlick") = false, py::arg("tint_reflection") = false,
             py::arg("mix_a") = -1, py::arg("mix_b") = -1, py::arg("mix_factor") = 0.5f,
             py::arg("mix_texture") = -1, py::arg("mix_channel") = "luminance",
             py::arg("mix_mode") = "constant", py::arg("mix_ior") = 1.5f,
             py::arg("normal_texture") = -1, py::arg("normal_strength") = 1.0f,
             py::arg("bump_texture") = -1, py::arg("bump_strength") = 1.0f,
             py::arg("bump_distance") = 1.0f, py::arg("emission_texture") = -1,
             py::arg("f82_tint") = std::array<float, 3>{1.0f, 1.0f, 1.0f},
             py::arg("visible_in_reflections") = true, py::arg("vertex_color") = false,
             py::arg("absorption") = std::array<float, 3>{0.0f, 0.0f, 0.0f})
        .def_readwrite("light_group", &Material::light_group,
                       "The light group of what emits with this material: an index into "
                       "Scene.light_groups, -1: none (docs/light_groups.md).")
        .def_readwrite("light_link_set", &Material::light_link_set,
                       "The light link set of what emits with this material: a bit of "
                       "Scene.light_link_receives' rows, 0-31 (docs/light_linking.md).")
        .def_readwrite("light_link_row", &Material::light_link_row,
                       "The row of Scene.light_link_receives and Scene.shadow_link_blocks that "
                       "says which link sets reach this material and which it shadows.");

    py::class_<Texture>(m, "Texture")
        .def(py::init(&make_texture), py::arg("pixels"), py::arg("wrap") = "repeat",
             py::arg("name") = "image",
             py::arg("uv_map") =
                 std::array<std::array<float, 3>, 2>{{{1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}}},
             py::arg("position_map") = py::none(), py::arg("interpolation") = "linear",
             "An image; uv_map ((a, b, c), (d, e, f)) looks it up at (a u + b v + c, "
             "d u + e v + f) for mesh uv (u, v) (Blender's Mapping node on the UVs). "
             "position_map ((a, b, c, d), (e, f, g, h)), where given, looks it up at "
             "(a x + b y + c z + d, e x + f y + g z + h) for the surface point's world "
             "position (x, y, z) instead (Generated and Object coordinates). interpolation: "
             "'linear' (bilinear between the four nearest texel centres) or 'closest' (the "
             "texel the point falls in), as Blender's Image Texture node.")
        .def_readonly("width", &Texture::width)
        .def_readonly("height", &Texture::height)
        .def_property_readonly("interpolation", [](const Texture& t) {
            return name_of(t.interpolation, kTextureInterpolations);
        });
}

}  // namespace glslppm
