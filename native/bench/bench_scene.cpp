#include "bench/bench_scene.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <stdexcept>

#include "gl/device_list.h"
#include "procedural/caustic_scene.h"
#include "procedural/cornell_box.h"
#include "procedural/instances_scene.h"
#include "procedural/million_scene.h"
#include "procedural/shapes.h"
#if __has_include("loaders/scene_file.h")
#include "loaders/scene_file.h"
#define GLSLPPM_HAS_SCENE_FILE 1
#endif

namespace glslppm {
namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
    return s.size() >= suffix.size() &&
           s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

constexpr float kFurnaceEmission = 1.0f, kFurnaceAlbedo = 0.5f;

// Inside a closed box every wall both emits and reflects uniformly, so the radiance is the
// same everywhere and in every direction: L = Le + a L for unlimited bounces. The camera
// looks at the middle of the -Z wall, far from the edges where a gather radius would reach
// past a wall's end.
Scene make_box_furnace() {
    auto mesh = std::make_shared<OwnedMesh>();
    const float h = 1.0f;
    const glm::vec3 q[6][4] = {
        {{-h, -h, -h}, {-h, -h, h}, {h, -h, h}, {h, -h, -h}},
        {{-h, h, -h}, {h, h, -h}, {h, h, h}, {-h, h, h}},
        {{-h, -h, -h}, {h, -h, -h}, {h, h, -h}, {-h, h, -h}},
        {{-h, -h, h}, {-h, h, h}, {h, h, h}, {h, -h, h}},
        {{-h, -h, -h}, {-h, h, -h}, {-h, h, h}, {-h, -h, h}},
        {{h, -h, -h}, {h, -h, h}, {h, h, h}, {h, h, -h}},
    };
    for (const auto& f : q) {
        const Shape s = make_quad(f[0], f[1], f[2], f[3]);
        mesh->append(s.positions, s.triangles, 0);
    }
    Scene scene = make_scene(mesh);
    Material wall;
    wall.color = glm::vec3(kFurnaceAlbedo);
    wall.emission = glm::vec3(kFurnaceEmission);
    scene.materials = {wall};
    scene.camera.fov_x = 30.0f * 3.14159265f / 180.0f;
    return scene;
}

}  // namespace

double furnace_radiance(int max_bounces) {
    // Cycles' Total (docs/bounces.md): N bounces keep N + 1 scatters, so the eye sees the
    // emission and N + 1 reflections of it.
    const double a = kFurnaceAlbedo;
    return kFurnaceEmission * (1.0 - std::pow(a, max_bounces + 2)) / (1.0 - a);
}

std::size_t parse_count(const std::string& text) {
    std::size_t used = 0;
    double value = 0.0;
    try {
        value = std::stod(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    const std::string suffix = text.substr(used);
    double scale = 1.0;
    if (suffix == "k" || suffix == "K")
        scale = 1e3;
    else if (suffix == "m" || suffix == "M")
        scale = 1e6;
    else if (!suffix.empty())
        used = 0;
    if (used == 0 || !(value > 0.0))
        throw std::invalid_argument("'" + text + "' is not a positive count (e.g. 1000, 100k, 4M)");
    return static_cast<std::size_t>(value * scale + 0.5);
}

namespace {

// `+motion` (docs/motion_blur.md): over a shutter of half a frame centred on it, every
// instance turns 10 degrees either way about its own z and drifts by a tenth of its size,
// and the camera dollies 2% of its distance to the origin (steps at -1, 0, +1).
void add_bench_motion(Scene& scene) {
    SceneMotion& m = scene.motion;
    m.shutter_open = -0.25f;
    m.shutter_length = 0.5f;
    const std::vector<float> times{-1.0f, 0.0f, 1.0f};
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        const glm::mat4& frame = scene.instances[i].to_world;
        InstanceMotion motion{static_cast<std::uint32_t>(i), {times, {}}};
        for (float t : times) {
            const float angle = 0.1745f * t, c = std::cos(angle), s = std::sin(angle);
            glm::mat4 turn(1.0f);
            turn[0] = glm::vec4(c, s, 0, 0);
            turn[1] = glm::vec4(-s, c, 0, 0);
            turn[3] = glm::vec4(0.1f * t, 0, 0, 1);
            motion.steps.to_world.push_back(frame * turn);
        }
        m.instances.push_back(std::move(motion));
    }
    const glm::vec3 eye(scene.camera.to_world[3]), forward(-scene.camera.to_world[2]);
    for (float t : times) {
        glm::mat4 c = scene.camera.to_world;
        c[3] = glm::vec4(eye + forward * (0.02f * t * glm::length(eye)), 1.0f);
        m.camera.times.push_back(t);
        m.camera.to_world.push_back(c);
    }
}

// `+deform` (docs/motion_blur.md): over the same shutter, every instance mesh's vertices
// ripple along z by up to 2% of the mesh's size (steps at -1, 0, +1), so that each pass
// rewrites the meshes' triangles and refits their bottom trees.
void add_bench_deformation(Scene& scene) {
    SceneMotion& m = scene.motion;
    m.shutter_open = -0.25f;
    m.shutter_length = 0.5f;
    for (std::size_t k = 0; k < scene.instance_meshes.size(); ++k) {
        const MeshView& mesh = scene.instance_meshes[k];
        glm::vec3 lo(1e30f), hi(-1e30f);
        for (const glm::vec3& p : mesh.positions) {
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        const float size = glm::length(hi - lo), wave = 12.0f / std::max(size, 1e-6f);
        MeshDeformation d{static_cast<std::uint32_t>(k), {-1.0f, 0.0f, 1.0f}, {}, {}};
        for (float t : d.times) {
            std::vector<glm::vec3> step(mesh.positions.begin(), mesh.positions.end());
            for (glm::vec3& p : step) p.z += 0.02f * size * t * std::sin(wave * (p.x + p.y));
            d.positions.push_back(std::move(step));
            if (!mesh.normals.empty())
                d.normals.emplace_back(mesh.normals.begin(), mesh.normals.end());
        }
        m.meshes.push_back(std::move(d));
    }
}

}  // namespace

Scene make_bench_scene(const std::string& spec, float aspect) {
    const std::string deform = "+deform";
    if (spec.size() > deform.size() && spec.ends_with(deform)) {
        Scene scene = make_bench_scene(spec.substr(0, spec.size() - deform.size()), aspect);
        add_bench_deformation(scene);
        return scene;
    }
    const std::string motion = "+motion";
    if (spec.size() > motion.size() && spec.ends_with(motion)) {
        Scene scene = make_bench_scene(spec.substr(0, spec.size() - motion.size()), aspect);
        add_bench_motion(scene);
        return scene;
    }
    if (spec == "cornell") return make_cornell_box();
    if (spec == "cornell-diffuse") {
        CornellBoxOptions options;
        options.mirror_sphere = options.glass_sphere = false;
        return make_cornell_box(options);
    }
    if (spec == "cornell-glossy") {
        CornellBoxOptions options;
        options.glossy = true;
        return make_cornell_box(options);
    }
    if (spec == "caustic") return make_caustic_scene();
    if (spec == "furnace") return make_box_furnace();
    if (spec == "million") return make_million_scene();
    if (spec.rfind("million:", 0) == 0) {
        MillionSceneOptions options;
        options.triangles = parse_count(spec.substr(8));
        return make_million_scene(options);
    }
    if (spec.rfind("instances:", 0) == 0) {
        // instances:COUNTxTRIANGLES, e.g. instances:10000x100k
        const std::string rest = spec.substr(10);
        const std::size_t x = rest.find('x');
        if (x == std::string::npos)
            throw std::invalid_argument("--scene " + spec + ": expected instances:COUNTxTRIANGLES");
        return make_instances_scene(parse_count(rest.substr(0, x)), parse_count(rest.substr(x + 1)));
    }
    if (ends_with(spec, ".gltf") || ends_with(spec, ".glb") || ends_with(spec, ".obj")) {
#ifdef GLSLPPM_HAS_SCENE_FILE
        LoadedScene loaded = load_scene_file(spec, aspect);
        for (const std::string& w : loaded.warnings)
            std::fprintf(stderr, "%s: %s\n", spec.c_str(), w.c_str());
        return std::move(loaded.scene);
#else
        (void)aspect;
        throw std::invalid_argument(
            "--scene " + spec + ": this build has no glTF loader (native/loaders/scene_file.h)");
#endif
    }
    throw std::invalid_argument("--scene '" + spec +
                                "' is not cornell, cornell-diffuse, cornell-glossy, caustic, furnace, "
                                "million[:N], instances:NxM "
                                "or a .gltf/.glb/.obj file (any of them +motion; instances:NxM +deform)");
}

double parse_number(const std::string& option, const std::string& text) {
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size() || !std::isfinite(v))
        throw std::invalid_argument(option + ": '" + text + "' is not a number");
    return v;
}

long long parse_integer(const std::string& option, const std::string& text) {
    const double v = parse_number(option, text);
    if (v != std::floor(v) || std::fabs(v) > 9.0e15)
        throw std::invalid_argument(option + ": '" + text + "' is not a whole number");
    return static_cast<long long>(v);
}

namespace {
std::string option_value(const std::string& option, int argc, char** argv, int& i) {
    if (i + 1 >= argc) throw std::invalid_argument(option + " needs a value");
    return argv[++i];
}
}  // namespace

double option_number(const std::string& option, int argc, char** argv, int& i) {
    return parse_number(option, option_value(option, argc, argv, i));
}

long long option_integer(const std::string& option, int argc, char** argv, int& i) {
    return parse_integer(option, option_value(option, argc, argv, i));
}

bool parse_render_option(int argc, char** argv, int& i, RenderSettings& settings,
                         std::string& scene_spec) {
    const std::string a = argv[i];
    auto number = [&] { return static_cast<double>(option_integer(a, argc, argv, i)); };
    auto text = [&] { return option_value(a, argc, argv, i); };
    if (a == "--width") settings.width = static_cast<int>(number());
    else if (a == "--height") settings.height = static_cast<int>(number());
    else if (a == "--photons") settings.photons_per_pass = static_cast<std::uint32_t>(number());
    else if (a == "--hash") settings.hash = parse_hash_mode(text());
    else if (a == "--rng") settings.rng = parse_rng_kind(text());
    else if (a == "--direct") settings.direct_light = parse_direct_light(text());
    else if (a == "--glossy-threshold")
        settings.glossy_threshold = static_cast<float>(option_number(a, argc, argv, i));
    else if (a == "--emitter-mis-fraction")
        settings.emitter_mis_fraction = static_cast<float>(option_number(a, argc, argv, i));
    else if (a == "--device") {
        // "0,1" or "all": one worker per device (estimator pppm).
        const std::vector<int> devices = gl::parse_device_list(text());
        settings.devices = devices.size() > 1 ? devices : std::vector<int>{};
        settings.device = devices[0];
    }
    else if (a == "--estimator") settings.estimator = parse_estimator(text());
    else if (a == "--vcm-techniques") settings.vcm_techniques = parse_vcm_techniques(text());
    else if (a == "--light-tracing") {
        const std::string v = text();
        if (v != "on" && v != "off")
            throw std::invalid_argument("--light-tracing: '" + v + "' is not on or off");
        settings.light_tracing = v == "on";
    }
    else if (a == "--scene") scene_spec = text();
    else if (a == "--instancing") settings.instancing = parse_instancing(text());
    else return false;
    return true;
}

}  // namespace glslppm
