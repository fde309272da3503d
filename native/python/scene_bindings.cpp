// Light, Camera and Scene: a scene's meshes are the caller's numpy arrays, used in place
// where dtype and layout fit (an ArrayOwner keeps them alive); and the procedural scenes.
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <array>
#include <cstring>
#include <optional>

#include "procedural/caustic_scene.h"
#include "procedural/cornell_box.h"
#include "python/bindings.h"
#include "python/enum_names.h"
#include "python/numpy_arrays.h"
#include "render/instancing.h"
#include "scene/scene.h"
#include "scene/scene_validation.h"

namespace glslppm {
namespace {

glm::vec3 vec3_of(std::array<float, 3> v) { return {v[0], v[1], v[2]}; }

// A 4x4 row-major numpy matrix (Blender's matrix_world) as column-major glm.
glm::mat4 mat4_of(const py::array_t<float, py::array::c_style | py::array::forcecast>& a,
                  const char* name) {
    if (a.ndim() != 2 || a.shape(0) != 4 || a.shape(1) != 4)
        throw py::value_error(std::string(name) + ": expected a 4x4 matrix");
    glm::mat4 out;
    for (int r = 0; r < 4; ++r)
        for (int k = 0; k < 4; ++k) out[k][r] = a.at(r, k);
    return out;
}

// One mesh in its own space from a dict of arrays (the keys of Scene's own arrays).
MeshView take_mesh(const py::handle& item, const std::string& name, ArrayOwner& owner) {
    if (!py::isinstance<py::dict>(item))
        throw py::value_error(name + ": expected a dict of arrays (positions, indices, normals, "
                              "uvs, material_ids)");
    const py::dict d = py::reinterpret_borrow<py::dict>(item);
    for (const auto& kv : d) {
        const std::string key = py::str(kv.first);
        if (key != "positions" && key != "indices" && key != "normals" && key != "uvs" &&
            key != "material_ids" && key != "tangents" && key != "colors")
            throw py::value_error(name + ": unknown key '" + key + "'");
    }
    if (!d.contains("positions") || !d.contains("indices"))
        throw py::value_error(name + ": needs positions and indices");
    MeshView m;
    const std::string n = name + ".";
    auto p = take_array<float>(d["positions"], (n + "positions").c_str(), 3, "float32");
    auto t = take_array<std::uint32_t>(d["indices"], (n + "indices").c_str(), 3, "uint32");
    owner.arrays.push_back(p);
    owner.arrays.push_back(t);
    m.positions = {reinterpret_cast<const glm::vec3*>(p.data()), std::size_t(p.shape(0))};
    m.triangles = {reinterpret_cast<const glm::uvec3*>(t.data()), std::size_t(t.shape(0))};
    if (d.contains("normals") && !d["normals"].is_none()) {
        auto a = take_array<float>(d["normals"], (n + "normals").c_str(), 3, "float32");
        owner.arrays.push_back(a);
        m.normals = {reinterpret_cast<const glm::vec3*>(a.data()), std::size_t(a.shape(0))};
    }
    if (d.contains("uvs") && !d["uvs"].is_none()) {
        auto a = take_array<float>(d["uvs"], (n + "uvs").c_str(), 2, "float32");
        owner.arrays.push_back(a);
        m.uvs = {reinterpret_cast<const glm::vec2*>(a.data()), std::size_t(a.shape(0))};
    }
    if (d.contains("tangents") && !d["tangents"].is_none()) {
        auto a = take_array<float>(d["tangents"], (n + "tangents").c_str(), 4, "float32");
        owner.arrays.push_back(a);
        m.tangents = {reinterpret_cast<const glm::vec4*>(a.data()), std::size_t(a.shape(0))};
    }
    if (d.contains("colors") && !d["colors"].is_none()) {
        auto a = take_array<float>(d["colors"], (n + "colors").c_str(), 3, "float32");
        owner.arrays.push_back(a);
        m.colors = {reinterpret_cast<const glm::vec3*>(a.data()), std::size_t(a.shape(0))};
    }
    if (d.contains("material_ids") && !d["material_ids"].is_none()) {
        auto a = take_array<std::uint32_t>(d["material_ids"], (n + "material_ids").c_str(), 0,
                                           "uint32");
        owner.arrays.push_back(a);
        m.material_ids = {a.data(), std::size_t(a.shape(0))};
    }
    return m;
}

// The instance table: (N, 4, 4) float32 row-major transforms (Blender's matrix_world), (N,)
// uint32 mesh indices and optional (N,) uint32 material offsets.
void add_instances(Scene& scene, ArrayOwner& owner, const py::object& meshes,
                   const py::object& matrices, const py::object& mesh_ids,
                   const py::object& offsets) {
    if (!meshes.is_none()) {
        std::size_t k = 0;
        for (const py::handle& item : py::list(meshes))
            scene.instance_meshes.push_back(
                take_mesh(item, "instance_meshes[" + std::to_string(k++) + "]", owner));
    }
    if (matrices.is_none()) {
        if (!mesh_ids.is_none() || !offsets.is_none())
            throw py::value_error("instance_mesh / instance_material_offset need instances");
        return;
    }
    if (!py::isinstance<py::array>(matrices))
        throw py::value_error("instances: expected a float32 array of shape (N, 4, 4)");
    const py::array a = py::reinterpret_borrow<py::array>(matrices);
    if (!a.dtype().is(py::dtype::of<float>()) || a.ndim() != 3 || a.shape(1) != 4 ||
        a.shape(2) != 4)
        throw py::value_error("instances: expected a float32 array of shape (N, 4, 4), got " +
                              describe(a));
    const auto m = py::array_t<float, py::array::c_style>::ensure(a);
    const std::size_t count = static_cast<std::size_t>(m.shape(0));
    if (mesh_ids.is_none()) throw py::value_error("instances: instance_mesh is needed too");
    const auto ids = take_array<std::uint32_t>(mesh_ids, "instance_mesh", 0, "uint32");
    if (static_cast<std::size_t>(ids.shape(0)) != count)
        throw py::value_error("instance_mesh: " + std::to_string(ids.shape(0)) +
                              " entries for " + std::to_string(count) + " instances");
    py::array_t<std::uint32_t> offs;
    if (!offsets.is_none()) {
        offs = take_array<std::uint32_t>(offsets, "instance_material_offset", 0, "uint32");
        if (static_cast<std::size_t>(offs.shape(0)) != count)
            throw py::value_error("instance_material_offset: " + std::to_string(offs.shape(0)) +
                                  " entries for " + std::to_string(count) + " instances");
    }
    scene.instances.resize(count);
    const float* f = m.data();
    for (std::size_t i = 0; i < count; ++i) {
        Instance& inst = scene.instances[i];
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) inst.to_world[c][r] = f[16 * i + 4 * r + c];
        inst.mesh = ids.data()[i];
        inst.material_offset = offsets.is_none() ? 0 : offs.data()[i];
    }
}

Scene make_py_scene(const py::object& positions, const py::object& indices,
                    const py::object& normals, const py::object& uvs,
                    const py::object& material_ids, std::vector<Material> materials,
                    std::vector<Light> lights, Camera camera, std::array<float, 3> environment,
                    std::vector<Texture> textures, int environment_texture,
                    const py::object& environment_to_world, const py::object& instance_meshes,
                    const py::object& instances, const py::object& instance_mesh,
                    const py::object& instance_material_offset, const py::object& tangents,
                    const py::object& colors) {
    deferred_release::drain();  // what renderers freed off Python's thread left
    auto owner = std::make_shared<ArrayOwner>();
    Scene scene;
    add_instances(scene, *owner, instance_meshes, instances, instance_mesh,
                  instance_material_offset);
    auto p = take_array<float>(positions, "positions", 3, "float32");
    auto t = take_array<std::uint32_t>(indices, "indices", 3, "uint32");
    owner->arrays.push_back(p);  // after the instance meshes' arrays, which it must keep too
    owner->arrays.push_back(t);
    scene.mesh.positions = {reinterpret_cast<const glm::vec3*>(p.data()), std::size_t(p.shape(0))};
    scene.mesh.triangles = {reinterpret_cast<const glm::uvec3*>(t.data()), std::size_t(t.shape(0))};
    if (!normals.is_none()) {
        auto n = take_array<float>(normals, "normals", 3, "float32");
        owner->arrays.push_back(n);
        scene.mesh.normals = {reinterpret_cast<const glm::vec3*>(n.data()), std::size_t(n.shape(0))};
    }
    if (!uvs.is_none()) {
        auto u = take_array<float>(uvs, "uvs", 2, "float32");
        owner->arrays.push_back(u);
        scene.mesh.uvs = {reinterpret_cast<const glm::vec2*>(u.data()), std::size_t(u.shape(0))};
    }
    if (!tangents.is_none()) {
        auto a = take_array<float>(tangents, "tangents", 4, "float32");
        owner->arrays.push_back(a);
        scene.mesh.tangents = {reinterpret_cast<const glm::vec4*>(a.data()), std::size_t(a.shape(0))};
    }
    if (!colors.is_none()) {
        auto a = take_array<float>(colors, "colors", 3, "float32");
        owner->arrays.push_back(a);
        scene.mesh.colors = {reinterpret_cast<const glm::vec3*>(a.data()), std::size_t(a.shape(0))};
    }
    if (!material_ids.is_none()) {
        auto m = take_array<std::uint32_t>(material_ids, "material_ids", 0, "uint32");
        owner->arrays.push_back(m);
        scene.mesh.material_ids = {m.data(), std::size_t(m.shape(0))};
    }
    scene.keepalive = owner;
    scene.materials = std::move(materials);
    scene.lights = std::move(lights);
    scene.camera = camera;
    scene.environment = vec3_of(environment);
    scene.textures = std::move(textures);
    scene.environment_texture = environment_texture;
    if (!environment_to_world.is_none()) {
        const glm::mat4 m = mat4_of(
            py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(environment_to_world),
            "environment_to_world");
        scene.environment_to_world = glm::mat3(m);
    }
    if (scene.materials.empty()) scene.materials.push_back(Material{});
    // Validate now, so that a bad array fails where the user passed it.
    validate_mesh(scene.mesh, static_cast<std::uint32_t>(scene.materials.size()));
    for (std::size_t k = 0; k < scene.instance_meshes.size(); ++k) {
        try {
            validate_mesh(scene.instance_meshes[k],
                          static_cast<std::uint32_t>(scene.materials.size()));
        } catch (const SceneError& e) {
            throw SceneError("instance_meshes[" + std::to_string(k) + "]: " + e.what());
        }
    }
    plan_instancing(scene, scene.materials, Instancing::Auto);  // checks the instances
    return scene;
}

}  // namespace

void bind_scene(py::module_& m) {
    py::class_<Light>(m, "Light")
        .def(py::init([](const std::string& kind, std::array<float, 3> color, float power,
                         std::array<float, 3> position, std::array<float, 3> direction,
                         float spot_size, float spot_blend, float radius, float angle,
                         bool spot_cosine, const py::object& to_world, const std::string& shape,
                         float size_x, float size_y, bool visible_to_camera, bool facing_disc) {
                 Light l;
                 l.kind = parse_name<LightKind>(kind, kLightKinds, "Light kind");
                 l.shape = parse_name<AreaShape>(shape, kAreaShapes, "Light shape");
                 if (!to_world.is_none())
                     l.to_world = mat4_of(py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(to_world),
                                          "Light to_world");
                 l.spot_cosine = spot_cosine;
                 l.facing_disc = facing_disc;
                 l.size_x = size_x;
                 l.size_y = size_y;
                 l.visible_to_camera = visible_to_camera;
                 // Numbers are checked, with the rest of the scene, by validate_scene when
                 // a renderer is made (native/scene/scene_validation.h).
                 l.color = vec3_of(color);
                 l.power = power;
                 l.position = vec3_of(position);
                 l.direction = vec3_of(direction);
                 l.spot_size = spot_size;
                 l.spot_blend = spot_blend;
                 l.radius = radius;
                 l.angle = angle;
                 return l;
             }),
             py::arg("kind") = "point", py::arg("color") = std::array<float, 3>{1, 1, 1},
             py::arg("power") = 1.0f, py::arg("position") = std::array<float, 3>{0, 0, 0},
             py::arg("direction") = std::array<float, 3>{0, 0, -1},
             py::arg("spot_size") = 0.785398f, py::arg("spot_blend") = 0.15f,
             py::arg("radius") = 0.0f, py::arg("angle") = 0.0f, py::arg("spot_cosine") = false,
             py::arg("to_world") = py::none(), py::arg("shape") = "square",
             py::arg("size_x") = 1.0f, py::arg("size_y") = 1.0f,
             py::arg("visible_to_camera") = true, py::arg("facing_disc") = false)
        .def_readwrite("light_group", &Light::light_group,
                       "Index into Scene.light_groups, -1: none (docs/light_groups.md).")
        .def_readwrite("light_link_set", &Light::light_link_set,
                       "Its light link set, a bit of Scene.light_link_receives' rows, 0-31 "
                       "(docs/light_linking.md).");

    py::class_<Camera>(m, "Camera")
        .def(py::init([](py::array_t<float, py::array::c_style | py::array::forcecast> to_world,
                         float fov_x, float shift_x, float shift_y, const std::string& projection,
                         float ortho_scale, float aperture_radius, float focus_distance,
                         float pixel_aspect, std::optional<std::array<int, 4>> region) {
                 if (to_world.ndim() != 2 || to_world.shape(0) != 4 || to_world.shape(1) != 4)
                     throw py::value_error("Camera to_world: expected a 4x4 matrix");
                 Camera c;
                 // Row-major numpy (Blender's matrix_world) into column-major glm.
                 for (int r = 0; r < 4; ++r)
                     for (int k = 0; k < 4; ++k) c.to_world[k][r] = to_world.at(r, k);
                 c.fov_x = fov_x;
                 c.shift_x = shift_x;
                 c.shift_y = shift_y;
                 c.projection = parse_name<Projection>(projection, kProjections, "Camera projection");
                 c.ortho_scale = ortho_scale;
                 c.aperture_radius = aperture_radius;
                 c.focus_distance = focus_distance;
                 c.pixel_aspect = pixel_aspect;
                 if (region) {
                     const auto [x, y, w, h] = *region;
                     c.region_x = x;
                     c.region_y = y;
                     c.full_width = w;
                     c.full_height = h;
                 }
                 return c;
             }),
             py::arg("to_world"), py::arg("fov_x") = 0.691111f, py::arg("shift_x") = 0.0f,
             py::arg("shift_y") = 0.0f, py::arg("projection") = "perspective",
             py::arg("ortho_scale") = 6.0f, py::arg("aperture_radius") = 0.0f,
             py::arg("focus_distance") = 10.0f, py::arg("pixel_aspect") = 1.0f,
             py::arg("region") = py::none());

    py::class_<Scene>(m, "Scene")
        .def(py::init(&make_py_scene), py::arg("positions"), py::arg("indices"),
             py::arg("normals") = py::none(), py::arg("uvs") = py::none(),
             py::arg("material_ids") = py::none(),
             py::arg("materials") = std::vector<Material>{},
             py::arg("lights") = std::vector<Light>{}, py::arg("camera") = Camera{},
             py::arg("environment") = std::array<float, 3>{0, 0, 0},
             py::arg("textures") = std::vector<Texture>{}, py::arg("environment_texture") = -1,
             py::arg("environment_to_world") = py::none(),
             py::arg("instance_meshes") = py::none(), py::arg("instances") = py::none(),
             py::arg("instance_mesh") = py::none(),
             py::arg("instance_material_offset") = py::none(), py::arg("tangents") = py::none(),
             py::arg("colors") = py::none())
        .def_readwrite("light_groups", &Scene::light_groups,
                       "Light groups' names (Blender's View Layer > Light Groups): each gets a "
                       "pass, Renderer.light_group_passes() (docs/light_groups.md).")
        .def_readwrite("world_light_group", &Scene::world_light_group,
                       "The world's light group: an index into light_groups, -1: none.")
        .def_readwrite("light_link_receives", &Scene::light_link_receives,
                       "Light linking: per row (Material.light_link_row) a mask whose bit s "
                       "says that emitters of link set s light it; empty: no links "
                       "(docs/light_linking.md).")
        .def_readwrite("shadow_link_blocks", &Scene::shadow_link_blocks,
                       "Shadow linking: per row a mask whose bit s says that materials of the "
                       "row shadow emitters of link set s (as many rows as light_link_receives).")
        .def_property_readonly("instance_count", [](const Scene& s) { return s.instances.size(); })
        .def_property_readonly("triangle_count", [](const Scene& s) { return s.mesh.triangles.size(); })
        .def("arrays", [](const Scene& s) {
            // Copies for rebuilding the scene elsewhere (scripts/cycles_reference.py).
            using namespace pybind11::literals;
            auto copy = [](const auto& span, py::ssize_t columns) {
                using T = typename std::decay_t<decltype(span[0][0])>;
                py::array_t<T> a({static_cast<py::ssize_t>(span.size()), columns});
                std::memcpy(a.mutable_data(), span.data(), span.size_bytes());
                return a;
            };
            py::list materials;
            for (const Material& mat : s.materials)
                materials.append(py::dict(
                    "kind"_a = kMaterialKinds[static_cast<int>(mat.kind)],
                    "roughness"_a = mat.roughness, "mix_a"_a = mat.mix_a, "mix_b"_a = mat.mix_b,
                    "mix_factor"_a = mat.mix_factor,
                    "color"_a = std::array<float, 3>{mat.color.x, mat.color.y, mat.color.z},
                    "ior"_a = mat.ior,
                    "emission"_a = std::array<float, 3>{mat.emission.x, mat.emission.y, mat.emission.z}));
            py::array_t<float> to_world({4, 4});  // row-major, like Blender's matrix_world
            for (int r = 0; r < 4; ++r)
                for (int k = 0; k < 4; ++k) to_world.mutable_at(r, k) = s.camera.to_world[k][r];
            py::array_t<std::uint32_t> ids(static_cast<py::ssize_t>(s.mesh.material_ids.size()));
            std::memcpy(ids.mutable_data(), s.mesh.material_ids.data(), s.mesh.material_ids.size_bytes());
            return py::dict("positions"_a = copy(s.mesh.positions, 3),
                            "indices"_a = copy(s.mesh.triangles, 3),
                            "normals"_a = copy(s.mesh.normals, 3), "material_ids"_a = ids,
                            "materials"_a = materials, "camera_to_world"_a = to_world,
                            "camera_fov_x"_a = s.camera.fov_x);
        }, "The scene's arrays, materials and camera as numpy copies and dicts.")
        .def_property_readonly("shares_memory_with_input", [](const Scene& s) {
            // True: the MeshView points into the numpy arrays given (no copy was made).
            if (!ArrayOwner::is_one(s.keepalive.get())) return false;
            auto owner = std::static_pointer_cast<const ArrayOwner>(s.keepalive);
            return !owner->arrays.empty() &&
                   py::array(owner->arrays[0]).data() == static_cast<const void*>(s.mesh.positions.data());
        });

    m.def("cornell_box", [](bool mirror_sphere, bool glass_sphere, int sphere_rings, bool glossy) {
        CornellBoxOptions o;
        o.mirror_sphere = mirror_sphere;
        o.glass_sphere = glass_sphere;
        o.sphere_rings = sphere_rings;
        o.glossy = glossy;
        return make_cornell_box(o);
    }, py::arg("mirror_sphere") = true, py::arg("glass_sphere") = true, py::arg("sphere_rings") = 48,
       py::arg("glossy") = false,
       "The built-in scene of glslppm-render: a Cornell box with a mirror and a glass sphere "
       "(glossy: rough gold, frosted glass and a plastic floor, glslppm-bench's cornell-glossy).");

    m.def("caustic_scene", [](int sphere_rings) {
        CausticSceneOptions o;
        o.sphere_rings = sphere_rings;
        return make_caustic_scene(o);
    }, py::arg("sphere_rings") = 64,
       "The benchmarks' caustic scene: a glass sphere focusing a small light onto a floor.");
}

}  // namespace glslppm
