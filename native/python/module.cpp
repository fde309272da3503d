// The pybind11 module `_glslppm`: scenes from numpy arrays (used in place where dtype and
// layout fit), renderers run in steps with the GIL released, films back as numpy arrays.
#include <epoxy/gl.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

#include "gl/device_limits.h"
#include "gl/egl_context.h"
#include "gl/gl_thread.h"
#include "gl/object_counts.h"
#include "image/exr.h"
#include "gl/shader_program.h"
#include "python/loaders_module.h"
#include "render/instancing.h"
#include "render/renderer.h"
#include "render/farm_merge.h"
#include "render/film_merge.h"
#include "render/pppm_schedule.h"
#include "render/tiled_render.h"
#include "scene/scene.h"
#include "scene/scene_hash.h"
#include "procedural/caustic_scene.h"
#include "procedural/cornell_box.h"

namespace py = pybind11;
using namespace glslppm;

namespace {

// A numpy array over the vector's own memory (moved, not copied): a film of 1920 x 1080 is
// 33 MB, which a copy would add to every progressive update.
py::array_t<float> array_owning(std::vector<float>&& values, std::vector<py::ssize_t> shape) {
    auto* owned = new std::vector<float>(std::move(values));
    const py::capsule base(owned, [](void* p) { delete static_cast<std::vector<float>*>(p); });
    return py::array_t<float>(shape, owned->data(), base);
}

// References to Python objects let go of where this thread may not hold the GIL. A
// Renderer is freed by whichever thread drops it last: a worker thread whose run() outlived
// close(), or a binding that released the GIL. Waiting for the GIL inside a destructor
// can deadlock (the GIL's holder may be waiting for this very thread), so such references
// are queued and released under the GIL: by a pending call, which Python runs on its main
// thread at its next bytecode, or by the next Scene made here, whichever comes first.
namespace deferred_release {

std::mutex& queue_mutex() {
    static std::mutex m;
    return m;
}
std::vector<PyObject*>& queue() {
    static std::vector<PyObject*> q;
    return q;
}

// GIL held.
void drain() {
    std::vector<PyObject*> objects;
    {
        std::lock_guard lock(queue_mutex());
        objects.swap(queue());
    }
    for (PyObject* object : objects) Py_DECREF(object);
}

int pending_call(void*) {
    drain();
    return 0;
}

// Any thread, GIL or not: takes over the references (objects are left empty).
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

std::string describe(const py::array& a) {
    std::string shape = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i)
        shape += (i ? ", " : "") + std::to_string(a.shape(i));
    shape += a.ndim() == 1 ? ",)" : ")";
    return "dtype " + std::string(py::str(a.dtype())) + ", shape " + shape;
}

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

const char* const kMaterialKinds[] = {"diffuse",     "conductor",   "dielectric", "plastic",
                                      "translucent", "transparent", "mix"};

template <typename Enum, std::size_t N>
Enum parse_name(const std::string& value, const char* const (&names)[N], const char* what) {
    for (std::size_t k = 0; k < N; ++k)
        if (value == names[k]) return static_cast<Enum>(k);
    std::string list;
    for (const char* n : names) list += (list.empty() ? "" : ", ") + std::string(n);
    throw py::value_error(std::string(what) + ": '" + value + "' is not one of " + list);
}

const char* const kTextureChannels[] = {"red", "green", "blue", "alpha", "luminance"};
const char* const kMixModes[] = {"constant", "fresnel", "facing"};

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

// An image from a (height, width, 4) uint8 (sRGB) or float32 (linear) array, row 0 at the
// bottom as in Blender's pixels.
Texture make_texture(const py::array& pixels, const std::string& wrap, const std::string& name,
                     std::array<std::array<float, 3>, 2> uv_map,
                     std::optional<std::array<std::array<float, 4>, 2>> position_map) {
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
    if (wrap == "repeat") t.wrap = TextureWrap::Repeat;
    else if (wrap == "clip") t.wrap = TextureWrap::Clip;
    else if (wrap == "extend") t.wrap = TextureWrap::Extend;
    else if (wrap == "mirror") t.wrap = TextureWrap::Mirror;
    else throw py::value_error("Texture wrap: '" + wrap + "' is not repeat, clip, extend or mirror");
    return t;
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
    owner->arrays = {p, t};
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

// The Python-facing renderer: close() frees the GPU now rather than at garbage collection.
// Each call holds its own reference, so close() on one thread while run() goes on in another
// cancels that run and frees the GPU when it returns, never under it.
class PyRenderer {
public:
    PyRenderer(const Scene& scene, const RenderSettings& settings, const CancelFlag* cancel)
        : renderer_(std::make_shared<Renderer>(scene, settings, cancel)) {}
    std::shared_ptr<Renderer> get() {
        std::lock_guard lock(mutex_);
        if (!renderer_) throw std::runtime_error("this Renderer was closed");
        return renderer_;
    }
    void close() {
        std::shared_ptr<Renderer> last;
        {
            std::lock_guard lock(mutex_);
            last = std::move(renderer_);
        }
        if (last) last->stop();
    }
    bool closed() const {
        std::lock_guard lock(mutex_);
        return !renderer_;
    }
    // Tests only: closes, letting go of this handle's reference on a thread Python has never
    // seen (as Blender's render job threads are), while the caller keeps the GIL released.
    void close_on_native_thread() {
        std::shared_ptr<Renderer> last;
        {
            std::lock_guard lock(mutex_);
            last = std::move(renderer_);
        }
        if (last) last->stop();
        std::thread([owned = std::move(last)]() mutable { owned.reset(); }).join();
    }

private:
    mutable std::mutex mutex_;
    std::shared_ptr<Renderer> renderer_;
};

py::dict stats_dict(const RenderStats& s) {
    py::dict d;
    d["passes"] = s.passes;
    d["photons_emitted"] = s.photons_emitted;
    d["rays"] = s.rays;
    d["seconds"] = s.seconds;
    d["photons_per_second"] = s.photons_per_second;
    d["rays_per_second"] = s.rays_per_second;
    d["mean_radius"] = s.mean_radius;
    d["max_radius"] = s.max_radius;
    d["initial_radius"] = s.initial_radius;
    d["renderer"] = s.renderer;
    d["variant"] = s.variant;
    d["direct_light"] = s.direct_light;
    d["estimator"] = s.estimator;
    d["scene_hash"] = s.scene_hash;
    d["radius_floor"] = s.radius_floor;
    py::list ranges;
    for (const auto& [first, end] : s.pass_ranges) ranges.append(py::make_tuple(first, end));
    d["pass_ranges"] = ranges;
    py::list devices;
    for (const DeviceStats& ds : s.devices) {
        py::dict e;
        e["device"] = ds.device;
        e["renderer"] = ds.renderer;
        e["passes"] = ds.passes;
        e["seconds"] = ds.seconds;
        e["passes_per_second"] = ds.passes_per_second;
        devices.append(e);
    }
    d["devices"] = devices;
    d["triangles"] = s.triangles;
    d["degenerate_dropped"] = s.degenerate_dropped;
    d["instancing"] = s.instancing;
    d["instancing_reason"] = s.instancing_reason;
    d["instances"] = s.instances;
    d["instanced_triangles"] = s.instanced_triangles;
    d["emitters"] = s.emitters;
    d["bvh_seconds"] = s.bvh_seconds;
    d["bvh_bytes_per_triangle"] = s.bvh_bytes_per_triangle;
    d["gpu_bytes"] = s.gpu_bytes;
    d["gpu_bytes_per_pixel"] = s.gpu_bytes_per_pixel;
    d["gpu_bytes_per_photon"] = s.gpu_bytes_per_photon;
    d["tiles"] = s.tiles;
    d["warnings"] = s.warnings;
    d["programs_compiled"] = s.programs_compiled;
    d["programs_reused"] = s.programs_reused;
    d["compile_seconds"] = s.compile_seconds;
    d["camera_updates"] = s.camera_updates;
    d["table_updates"] = s.table_updates;
    d["film_resets"] = s.film_resets;
    d["eye_seconds"] = s.eye_seconds;
    d["photon_seconds"] = s.photon_seconds;
    d["hash_seconds"] = s.hash_seconds;
    d["gather_seconds"] = s.gather_seconds;
    return d;
}

}  // namespace

// Renderer.render_pass(es): each pass as a height x width x channels array, resolved
// together (one read back of the pass films).
static py::dict render_pass_arrays(PyRenderer& r, const std::vector<std::string>& names) {
    std::vector<RenderPass> wanted;
    for (const std::string& name : names) wanted.push_back(parse_render_pass(name));
    std::vector<std::vector<float>> images;
    const std::shared_ptr<Renderer> renderer = r.get();
    {
        py::gil_scoped_release release;
        images = renderer->render_passes(wanted);
    }
    const RenderSettings& s = renderer->settings();
    py::dict out;
    for (std::size_t k = 0; k < wanted.size(); ++k) {
        const int channels = render_pass_info(wanted[k]).channels;
        py::array_t<float> a({s.height, s.width, channels});
        float* dst = a.mutable_data();
        const std::vector<float>& image = images[k];
        for (std::size_t i = 0; i < image.size() / 4; ++i)
            for (int c = 0; c < channels; ++c) dst[i * channels + c] = image[4 * i + c];
        out[py::str(names[k])] = a;
    }
    return out;
}

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
             py::arg("absorption") = std::array<float, 3>{0.0f, 0.0f, 0.0f});

    py::class_<Texture>(m, "Texture")
        .def(py::init(&make_texture), py::arg("pixels"), py::arg("wrap") = "repeat",
             py::arg("name") = "image",
             py::arg("uv_map") =
                 std::array<std::array<float, 3>, 2>{{{1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}}},
             py::arg("position_map") = py::none(),
             "An image; uv_map ((a, b, c), (d, e, f)) looks it up at (a u + b v + c, "
             "d u + e v + f) for mesh uv (u, v) (Blender's Mapping node on the UVs). "
             "position_map ((a, b, c, d), (e, f, g, h)), where given, looks it up at "
             "(a x + b y + c z + d, e x + f y + g z + h) for the surface point's world "
             "position (x, y, z) instead (Generated and Object coordinates).")
        .def_readonly("width", &Texture::width)
        .def_readonly("height", &Texture::height);

    py::class_<Light>(m, "Light")
        .def(py::init([](const std::string& kind, std::array<float, 3> color, float power,
                         std::array<float, 3> position, std::array<float, 3> direction,
                         float spot_size, float spot_blend, float radius, float angle,
                         bool spot_cosine, const py::object& to_world, const std::string& shape,
                         float size_x, float size_y, bool visible_to_camera) {
                 Light l;
                 if (kind == "point") l.kind = LightKind::Point;
                 else if (kind == "spot") l.kind = LightKind::Spot;
                 else if (kind == "sun") l.kind = LightKind::Sun;
                 else if (kind == "area") l.kind = LightKind::Area;
                 else throw py::value_error("Light kind: '" + kind + "' is not one of point, spot, sun, area");
                 if (shape == "square") l.shape = AreaShape::Square;
                 else if (shape == "rectangle") l.shape = AreaShape::Rectangle;
                 else if (shape == "disk") l.shape = AreaShape::Disk;
                 else if (shape == "ellipse") l.shape = AreaShape::Ellipse;
                 else throw py::value_error("Light shape: '" + shape + "' is not one of square, rectangle, disk, ellipse");
                 if (!to_world.is_none())
                     l.to_world = mat4_of(py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(to_world),
                                          "Light to_world");
                 l.spot_cosine = spot_cosine;
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
             py::arg("visible_to_camera") = true);

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
                 if (projection == "perspective") c.projection = Projection::Perspective;
                 else if (projection == "orthographic") c.projection = Projection::Orthographic;
                 else throw py::value_error("Camera projection: '" + projection + "' is not perspective or orthographic");
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

    // The keyword defaults are RenderSettings' own (native/render/settings.h).
    const RenderSettings defaults;
    py::class_<RenderSettings>(m, "Settings")
        .def(py::init([](int width, int height, std::uint32_t photons_per_pass, float alpha,
                         float initial_radius, float radius_scale, int max_bounces,
                         const std::string& hash,
                         const std::string& rng, int device, std::uint64_t seed, int leaf_size,
                         bool profile, bool full_variant, int max_texture_size,
                         bool transparent, bool transparent_glass,
                         const std::string& direct_light, float glossy_threshold,
                         const std::string& estimator, std::vector<int> devices,
                         std::uint64_t first_pass, const std::string& instancing,
                         std::uint64_t max_block_bytes, std::vector<std::string> passes,
                         const std::string& bump_shadowing, int max_diffuse_bounces,
                         int max_glossy_bounces, int max_transmission_bounces) {
                 RenderSettings s;
                 s.width = width;
                 s.height = height;
                 s.photons_per_pass = photons_per_pass;
                 s.alpha = alpha;
                 s.initial_radius = initial_radius;
                 s.radius_scale = radius_scale;
                 s.max_bounces = max_bounces;
                 s.max_diffuse_bounces = max_diffuse_bounces;
                 s.max_glossy_bounces = max_glossy_bounces;
                 s.max_transmission_bounces = max_transmission_bounces;
                 s.hash = parse_hash_mode(hash);
                 s.rng = parse_rng_kind(rng);
                 s.direct_light = parse_direct_light(direct_light);
                 s.device = device;
                 s.seed = seed;
                 s.leaf_size = leaf_size;
                 s.profile = profile;
                 s.full_variant = full_variant;
                 s.max_texture_size = max_texture_size;
                 s.transparent = transparent;
                 s.transparent_glass = transparent_glass;
                 s.glossy_threshold = glossy_threshold;
                 s.estimator = parse_estimator(estimator);
                 s.devices = std::move(devices);
                 s.first_pass = first_pass;
                 s.instancing = parse_instancing(instancing);
                 s.max_block_bytes = max_block_bytes;
                 s.bump_shadowing = parse_bump_shadowing(bump_shadowing);
                 for (const std::string& name : passes) {
                     for (RenderPass p : parse_render_pass_list(name))
                         if (std::find(s.passes.begin(), s.passes.end(), p) == s.passes.end())
                             s.passes.push_back(p);
                 }
                 validate(s);
                 return s;
             }),
             py::arg("width") = defaults.width, py::arg("height") = defaults.height,
             py::arg("photons_per_pass") = defaults.photons_per_pass,
             py::arg("alpha") = defaults.alpha, py::arg("initial_radius") = defaults.initial_radius,
             py::arg("radius_scale") = defaults.radius_scale,
             py::arg("max_bounces") = defaults.max_bounces, py::arg("hash") = to_string(defaults.hash),
             py::arg("rng") = to_string(defaults.rng), py::arg("device") = defaults.device,
             py::arg("seed") = defaults.seed, py::arg("leaf_size") = defaults.leaf_size,
             py::arg("profile") = defaults.profile, py::arg("full_variant") = defaults.full_variant,
             py::arg("max_texture_size") = defaults.max_texture_size,
             py::arg("transparent") = defaults.transparent,
             py::arg("transparent_glass") = defaults.transparent_glass,
             py::arg("direct_light") = to_string(defaults.direct_light),
             py::arg("glossy_threshold") = defaults.glossy_threshold,
             py::arg("estimator") = to_string(defaults.estimator),
             py::arg("devices") = defaults.devices, py::arg("first_pass") = defaults.first_pass,
             py::arg("instancing") = to_string(defaults.instancing),
             py::arg("max_block_bytes") = defaults.max_block_bytes,
             py::arg("passes") = std::vector<std::string>{},
             py::arg("bump_shadowing") = to_string(defaults.bump_shadowing),
             py::arg("max_diffuse_bounces") = defaults.max_diffuse_bounces,
             py::arg("max_glossy_bounces") = defaults.max_glossy_bounces,
             py::arg("max_transmission_bounces") = defaults.max_transmission_bounces)
        .def_readonly("width", &RenderSettings::width)
        .def_readonly("max_bounces", &RenderSettings::max_bounces)
        .def_readonly("max_diffuse_bounces", &RenderSettings::max_diffuse_bounces)
        .def_readonly("max_glossy_bounces", &RenderSettings::max_glossy_bounces)
        .def_readonly("max_transmission_bounces", &RenderSettings::max_transmission_bounces)
        .def_readonly("max_block_bytes", &RenderSettings::max_block_bytes)
        .def_readonly("height", &RenderSettings::height)
        .def_readonly("radius_scale", &RenderSettings::radius_scale)
        .def_property_readonly("estimator", [](const RenderSettings& s) { return to_string(s.estimator); })
        .def_readonly("devices", &RenderSettings::devices)
        .def_readonly("first_pass", &RenderSettings::first_pass)
        // Every other setting readable too, so that callers (the add-on's defaults test)
        // can compare theirs with the module's.
        .def_readonly("photons_per_pass", &RenderSettings::photons_per_pass)
        .def_readonly("alpha", &RenderSettings::alpha)
        .def_readonly("initial_radius", &RenderSettings::initial_radius)
        .def_readonly("device", &RenderSettings::device)
        .def_readonly("seed", &RenderSettings::seed)
        .def_readonly("leaf_size", &RenderSettings::leaf_size)
        .def_readonly("max_texture_size", &RenderSettings::max_texture_size)
        .def_readonly("transparent", &RenderSettings::transparent)
        .def_readonly("transparent_glass", &RenderSettings::transparent_glass)
        .def_readonly("glossy_threshold", &RenderSettings::glossy_threshold)
        .def_property_readonly("hash", [](const RenderSettings& s) { return to_string(s.hash); })
        .def_property_readonly("rng", [](const RenderSettings& s) { return to_string(s.rng); })
        .def_property_readonly("direct_light",
                               [](const RenderSettings& s) { return to_string(s.direct_light); })
        .def_property_readonly("instancing",
                               [](const RenderSettings& s) { return to_string(s.instancing); })
        .def_property_readonly("bump_shadowing",
                               [](const RenderSettings& s) { return to_string(s.bump_shadowing); })
        .def_property_readonly("passes", [](const RenderSettings& s) {
            std::vector<std::string> names;
            for (RenderPass p : s.passes) names.push_back(render_pass_info(p).name);
            return names;
        }, "The render passes beside Combined, by name (docs/passes.md).");

    // Set from any thread while a Renderer is being constructed with it: the construction
    // (BVH build, GL set-up) stops within milliseconds and raises Cancelled.
    py::class_<CancelFlag, std::shared_ptr<CancelFlag>>(m, "CancelFlag")
        .def(py::init([] { return std::make_shared<CancelFlag>(false); }))
        .def("set", [](CancelFlag& flag) { flag = true; })
        .def("clear", [](CancelFlag& flag) { flag = false; })
        .def_property_readonly("is_set", [](const CancelFlag& flag) { return flag.load(); });

    py::class_<PyRenderer>(m, "Renderer")
        .def(py::init([](const Scene& scene, const RenderSettings& settings,
                         std::shared_ptr<CancelFlag> cancel) {
                 py::gil_scoped_release release;
                 return std::make_unique<PyRenderer>(scene, settings, cancel.get());
             }),
             py::arg("scene"), py::arg("settings"), py::arg("cancel") = nullptr)
        .def("run", [](PyRenderer& r, int passes) {
            if (passes < 0) throw py::value_error("passes: must be >= 0");
            py::gil_scoped_release release;
            return r.get()->run(passes);
        }, py::arg("passes") = 1,
        "Runs that many passes; returns how many ran (fewer after cancel() or close()).")
        .def("run_passes", [](PyRenderer& r, std::vector<std::uint64_t> indices) {
            py::gil_scoped_release release;
            return r.get()->run_passes(indices);
        }, py::arg("indices"),
        "PPPM: runs exactly these pass indices over the workers; returns how many ran.")
        .def("farm_attributes", [](PyRenderer& r, py::object frame_scene,
                                   py::object frame_settings) {
            const std::shared_ptr<Renderer> renderer = r.get();
            RenderStats s;
            RenderSettings settings = renderer->settings();
            if (!frame_settings.is_none()) settings = frame_settings.cast<RenderSettings>();
            const Scene* frame = frame_scene.is_none() ? nullptr : &frame_scene.cast<const Scene&>();
            {
                py::gil_scoped_release release;
                s = renderer->stats();
                if (frame) s.scene_hash = scene_hash_hex(*frame);
            }
            return farm_attributes(settings, s);
        }, py::arg("frame_scene") = py::none(), py::arg("frame_settings") = py::none(),
           "The EXR header attributes glslppm-merge reads: estimator, seed, settings, scene "
           "hash, pass ranges and passes. A tile's renderer (tile_render_inputs) is given the "
           "whole frame's scene and settings, whose camera and size the header names.")
        .def("write_passes_exr", [](PyRenderer& r, const std::string& path) {
            const std::shared_ptr<Renderer> renderer = r.get();
            py::gil_scoped_release release;
            const RenderSettings& settings = renderer->settings();
            write_multilayer_exr(path, settings.width, settings.height,
                                 render_pass_layers(renderer->film(), settings.passes,
                                                    renderer->render_passes(settings.passes)),
                                 farm_attributes(settings, renderer->stats()));
        }, py::arg("path"),
           "Writes Combined and every enabled render pass as one multi-layer EXR with the farm "
           "attributes, as glslppm-render --passes-out does: a farm job's file for "
           "glslppm-merge.")
        .def("cancel", [](PyRenderer& r) { r.get()->cancel(); },
             "Stops a run in progress (on another thread) after its current pass.")
        .def("reset_film", [](PyRenderer& r) {
            py::gil_scoped_release release;
            r.get()->reset_film();
        }, "Starts the image again from no passes; scene, BVH and programs stay.")
        .def("set_camera", [](PyRenderer& r, const Camera& camera) {
            py::gil_scoped_release release;
            return r.get()->set_camera(camera);
        }, py::arg("camera"),
        "Looks through another camera and starts the image again, without a BVH build. "
        "False (nothing changed) when the camera needs other programs: make a new Renderer.")
        .def("update_tables", [](PyRenderer& r, const Scene& scene) {
            py::gil_scoped_release release;
            return r.get()->update_tables(scene);
        }, py::arg("scene"),
        "Takes the materials, lights, world and camera of a scene with the same geometry and "
        "starts the image again, without a BVH build. False (nothing changed) when they need "
        "other programs, images or geometry: make a new Renderer.")
        .def("_debug_set_photons_emitted", [](PyRenderer& r, std::uint64_t count) {
            py::gil_scoped_release release;
            r.get()->debug_set_photons_emitted(count);
        }, "Tests only: sets the 64-bit count of photon paths started.")
        .def("film", [](PyRenderer& r, std::optional<py::array> out, bool bottom_up) -> py::array {
            const std::shared_ptr<Renderer> renderer = r.get();
            const RenderSettings& s = renderer->settings();
            if (out) {
                // Into the caller's array: a viewport's redraws reuse one, writing no new pages.
                const bool fits = out->dtype().is(py::dtype::of<float>()) && out->ndim() == 3 &&
                                  out->shape(0) == s.height && out->shape(1) == s.width &&
                                  out->shape(2) == 4 && out->writeable() &&
                                  (out->flags() & py::array::c_style);
                if (!fits)
                    throw py::value_error("film(out): out must be a writable C-contiguous float32 "
                                          "array of shape (" + std::to_string(s.height) + ", " +
                                          std::to_string(s.width) + ", 4)");
                const std::span<float> pixels(static_cast<float*>(out->mutable_data()),
                                              static_cast<std::size_t>(out->size()));
                py::gil_scoped_release release;
                renderer->film_into(pixels, bottom_up);
                return *out;
            }
            if (bottom_up) {
                py::array_t<float> flipped({s.height, s.width, 4});
                const std::span<float> pixels(flipped.mutable_data(),
                                              static_cast<std::size_t>(flipped.size()));
                py::gil_scoped_release release;
                renderer->film_into(pixels, true);
                return std::move(flipped);
            }
            std::vector<float> film;
            {
                py::gil_scoped_release release;
                film = renderer->film();
            }
            return array_owning(std::move(film), {s.height, s.width, 4});
        }, py::arg("out") = py::none(), py::arg("bottom_up") = false,
        "Linear RGBA, height x width x 4 float32, row 0 at the top (bottom_up: at the bottom, "
        "as Blender's images store rows). out: an array of that shape to fill instead of a new "
        "one (returned).")
        .def("render_pass", [](PyRenderer& r, const std::string& name) {
            const py::dict images = render_pass_arrays(r, {name});
            return py::object(images[py::str(name)]);
        }, py::arg("name"),
        "One of the settings' passes (docs/passes.md) as film() gives Combined: height x width "
        "x 1 (depth) or 3, the mean over the passes run.")
        .def("render_passes", &render_pass_arrays, py::arg("names"),
             "Several passes as render_pass() gives one, {name: array}, with one read back "
             "from the GPU.")
        .def_property_readonly("settings", [](PyRenderer& r) { return r.get()->settings(); },
                               "A copy of the settings the renderer was made with.")
        .def("photons", [](PyRenderer& r) {
            std::vector<float> photons;
            {
                py::gil_scoped_release release;
                photons = r.get()->photons();
            }
            const auto count = static_cast<py::ssize_t>(photons.size() / 12);
            return array_owning(std::move(photons), {count, 12});
        })
        .def("stats", [](PyRenderer& r) {
            RenderStats s;
            {
                py::gil_scoped_release release;
                s = r.get()->stats();
            }
            return stats_dict(s);
        })
        .def("close", [](PyRenderer& r) {
            py::gil_scoped_release release;
            r.close();
        }, "Frees the GL context and every GPU buffer now (also done on garbage collection).")
        .def_property_readonly("closed", [](const PyRenderer& r) { return r.closed(); })
        .def("_debug_close_on_native_thread", [](PyRenderer& r) {
            py::gil_scoped_release release;
            r.close_on_native_thread();
        }, "Tests only: close(), the last reference dropped on a thread that is not Python's.");
    // Tests only: a Scene's arrays released on a thread Python has never seen, as a copy of a
    // Scene freed inside a worker would release them.
    static std::unique_ptr<Scene> held_scene;
    m.def("_debug_hold_scene", [](const Scene& scene) {
        held_scene = std::make_unique<Scene>(scene);
    }, "Tests only: keeps a copy of the scene (sharing its arrays) in the module.");
    m.def("_debug_drop_held_scene_on_native_thread", [] {
        py::gil_scoped_release release;
        std::thread([owned = std::move(held_scene)]() mutable { owned.reset(); }).join();
    }, "Tests only: frees the kept copy on a new thread, the GIL released.");
    m.def("_debug_deferred_releases", [] {
        std::lock_guard lock(deferred_release::queue_mutex());
        return deferred_release::queue().size();
    }, "Tests only: references to Python objects freed off Python's thread, not yet released.");

    // Frames larger than one storage buffer holds, as image tiles (render/tiled_render.h).
    auto tile_tuple = [](const Tile& t) { return py::make_tuple(t.x, t.y, t.width, t.height); };
    auto plan_dict = [tile_tuple](const TilePlan& plan) {
        py::list tiles;
        for (const Tile& t : plan.tiles) tiles.append(tile_tuple(t));
        py::dict d;
        d["tiles"] = tiles;
        d["gpu_bytes_per_pixel"] = plan.gpu_bytes_per_pixel;
        d["block_bytes_per_pixel"] = plan.block_bytes_per_pixel;
        d["largest_block"] = plan.largest_block;
        return d;
    };
    m.def("render_passes", [] {
        py::list passes;
        for (const RenderPassInfo& p : render_pass_catalog()) {
            py::dict d;
            d["name"] = p.name;
            d["blender"] = p.blender;
            d["blender_3x"] = render_pass_blender_3x(p.pass);
            d["channels"] = p.channels;
            d["channel_names"] = p.channel_names;
            d["light"] = p.light;
            passes.append(d);
        }
        return passes;
    }, "Every render pass beside Combined: its name, Blender's names (4.x, 3.x), channels, and "
       "whether it is part of Combined's light split (docs/passes.md).");
    m.def("plan_tiles", [plan_dict](const Scene& scene, const RenderSettings& settings) {
        TilePlan plan;
        {
            py::gil_scoped_release release;
            plan = plan_tiles(scene, settings);
        }
        return plan_dict(plan);
    }, py::arg("scene"), py::arg("settings"),
       "The image tiles (x, y, width, height; y from the top) that a render of this size "
       "needs on its device, decided before allocating: one when it fits. Also the per-pixel "
       "bytes and the device's largest storage buffer.");
    m.def("tile_render_inputs", [](const Scene& scene, const RenderSettings& settings,
                                   std::array<int, 4> tile) {
        const Tile t{tile[0], tile[1], tile[2], tile[3]};
        Scene s = scene;
        s.camera = tile_camera(scene.camera, settings, t);
        return py::make_tuple(s, tile_settings(settings, t));
    }, py::arg("scene"), py::arg("settings"), py::arg("tile"),
       "The (scene, settings) that render one tile (x, y, width, height) of the frame: its "
       "camera looks through the tile's window, with the whole frame's radius and streams.");
    m.def("render_tiled", [plan_dict, tile_tuple](const Scene& scene, const RenderSettings& settings,
                                                  int passes, py::object on_tile,
                                                  std::shared_ptr<CancelFlag> cancel) {
        TiledImage image;
        {
            py::gil_scoped_release release;
            const TilePlan plan = plan_tiles(scene, settings);
            TileDone done;
            if (!on_tile.is_none()) {
                done = [&](std::size_t index, const Tile& t, const std::vector<float>& rgba) {
                    py::gil_scoped_acquire acquire;
                    py::array_t<float> a({t.height, t.width, 4});
                    std::memcpy(a.mutable_data(), rgba.data(), rgba.size() * sizeof(float));
                    const py::object keep = on_tile(index, tile_tuple(t), a);
                    return keep.is_none() || keep.cast<bool>();
                };
            }
            image = render_tiled(scene, settings, passes, plan, done, cancel.get());
        }
        py::array_t<float> out({settings.height, settings.width, 4});
        std::memcpy(out.mutable_data(), image.rgba.data(), image.rgba.size() * sizeof(float));
        py::dict stats = stats_dict(image.stats);
        stats["plan"] = plan_dict(image.plan);
        return py::make_tuple(out, stats);
    }, py::arg("scene"), py::arg("settings"), py::arg("passes"), py::arg("on_tile") = py::none(),
       py::arg("cancel") = nullptr,
       "Renders the frame as the tiles plan_tiles gives, `passes` SPPM passes each (each tile "
       "traces its own photons: time grows with the tile count). on_tile(index, (x, y, w, h), "
       "rgba) after each; returning False stops. Returns (rgba, stats).");

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
    m.def("pppm_pass_radius", &pppm_pass_radius, py::arg("initial_radius"), py::arg("floor"),
          py::arg("pass_index"), py::arg("alpha"),
          "PPPM's radius of a pass: initial_radius s(i), never below floor.");
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

    bind_loaders(m);  // load_scene, load_texture, scene_contents (python/loaders_module.cpp)
}
