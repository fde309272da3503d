// glslppm-render: renders the built-in Cornell box or a glTF/OBJ scene file to an EXR.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gl/device_list.h"
#include "image/exr.h"
#include "image/image_file.h"
#include "loaders/scene_file.h"
#include "render/farm_merge.h"
#include "render/renderer.h"
#include "scene/light_groups.h"
#include "render/tiled_render.h"
#include "procedural/cornell_box.h"

using namespace glslppm;

namespace {

struct Options {
    RenderSettings settings;
    int passes = 0;
    double seconds = 0.0;
    std::string out;
    bool multilayer = false;  // --passes-out: one multi-layer EXR with settings.passes
    bool json = false;
    std::string scene_file;   // empty: the built-in Cornell box
    SceneFileOptions scene_options;
    std::string environment;  // equirectangular map
    bool has_environment_color = false;
    glm::vec3 environment_color{0.0f};
    int light_groups = 0;     // --light-groups N: the emitters dealt into N groups
};

// The CLI renders final images, so its size and photon count are larger than
// RenderSettings' (256 x 256, 65,536: the module's and the add-on's quick defaults); every
// other default is RenderSettings' own.
constexpr int kCliSize = 512;
constexpr std::uint32_t kCliPhotons = 262144;

std::string usage() {
    const RenderSettings d;
    char text[6144];
    std::snprintf(
        text, sizeof text,
        "usage: glslppm-render [options]\n"
        "  Renders the built-in Cornell box (diffuse walls, a mirror and a glass sphere, a\n"
        "  ceiling light) with stochastic progressive photon mapping.\n"
        "  --width N --height N      image size (default %d x %d; the module's is %d x %d)\n"
        "  --passes N                passes to run (default 64 unless --seconds is given)\n"
        "  --seconds S               stop after S seconds (with --passes: whichever comes first)\n"
        "  --photons N               photons per pass (default %u; the module's is %u)\n"
        "  --alpha A                 SPPM alpha (default %g)\n"
        "  --radius R                initial radius (default: automatic)\n"
        "  --radius-scale S          multiplies the automatic radius (default %g)\n"
        "  --max-bounces N           Cycles' Light Paths Total: scatters before a path's last\n"
        "                            (default %d; --max-depth is accepted for scripts written\n"
        "                            before; docs/bounces.md)\n"
        "  --diffuse-bounces N       Cycles' per-kind limits (default %d each: the total alone;\n"
        "  --glossy-bounces N        Cycles' own defaults are 4, 4 and 12)\n"
        "  --transmission-bounces N\n"
        "  --hash stochastic|exact   photon hashing (default %s)\n"
        "  --rng pcg|paper           generator (default %s; docs/rng.md says why)\n"
        "  --direct sampled|photons  direct light by light sampling or by photons alone\n"
        "                            (default %s; docs/direct_light.md says why;\n"
        "                            sampled-no-mis: light samples without MIS, the baseline)\n"
        "  --emitter-mis-fraction Q  probability of a Lambertian point's BSDF sample of\n"
        "                            emitters, per 64 pixels and pass (default %g; (0, 1])\n"
        "  --instancing auto|two-level|flattened  how instances are traced (default %s;\n"
        "                            docs/instancing.md)\n"
        "  --device N|N,M,...|all    EGL device index (default $GLSLPPM_DEVICE or the first GPU);\n"
        "                            several (or every GPU: all) run one worker each (pppm)\n"
        "  --estimator sppm|pppm|vcm progressive per-pixel radii (SPPM), a radius per pass\n"
        "                            index whose passes merge anywhere (PPPM; default %s),\n"
        "                            or VCM's independent passes (docs/vcm.md)\n"
        "  --vcm-techniques pt|lt|pt+lt|pt+lt+vm  vcm: path tracing alone (default), light\n"
        "                            tracing alone, both weighted together, or with vertex\n"
        "                            merging of caustics seen through glass besides\n"
        "  --first-pass K            pppm: run passes K, K+1, ... (a farm job's share)\n"
        "  --light-tracing on|off    caustics seen directly by light tracing (default %s;\n"
        "                            docs/light_tracing.md)\n"
        "  --seed N                  random seed (default %llu)\n"
        "  --light-groups N          deal the emitters (emissive materials, lights, the world)\n"
        "                            into N light groups group0...: --passes-out writes each\n"
        "                            group's Combined_groupK layer (docs/light_groups.md)\n"
        "  --scene FILE              render a .gltf, .glb or .obj file instead (a file without a\n"
        "                            camera gets one that frames the whole scene)\n"
        "  --mtl-convention standard|glslppm2015  how an .obj's MTL reads: the MTL specification\n"
        "                            (default), or the original glslppm's scene files (Ka a\n"
        "                            light, Ks 1 with Ns 100 a mirror, 'glass*' a glass)\n"
        "  --environment FILE        equirectangular environment map (.hdr, .exr, .png, .jpg)\n"
        "  --environment-color R,G,B environment radiance (default 1,1,1 with a map, else 0)\n"
        "  --max-block-bytes N       cap the per-pixel buffers below the GPU's largest storage\n"
        "                            buffer (tests: forces image tiles on small images)\n"
        "  --out FILE.exr            write the image\n"
        "  --passes-out all|combined|depth,normal,...  write --out as one multi-layer EXR of\n"
        "                            Combined and these passes, named as Blender names them:\n"
        "                            depth, normal, denoising_normal, denoising_albedo,\n"
        "                            emission, environment, direct, indirect, caustics\n"
        "                            (docs/passes.md)\n"
        "  A frame whose visible points exceed one storage buffer renders as bands of rows,\n"
        "  one after another, each with its own photon passes (--passes, not --seconds).\n"
        "  --json                    print the final statistics as one JSON object\n",
        kCliSize, kCliSize, d.width, d.height, kCliPhotons, d.photons_per_pass, d.alpha,
        d.radius_scale, d.max_bounces, d.max_diffuse_bounces, to_string(d.hash).c_str(), to_string(d.rng).c_str(),
        to_string(d.direct_light).c_str(), d.emitter_mis_fraction, to_string(d.instancing).c_str(),
        to_string(d.estimator).c_str(), d.light_tracing ? "on" : "off",
        static_cast<unsigned long long>(d.seed));
    return text;
}

glm::vec3 parse_color(const std::string& option, const std::string& text) {
    glm::vec3 c;
    char* end = nullptr;
    const char* p = text.c_str();
    for (int i = 0; i < 3; ++i) {
        c[i] = std::strtof(p, &end);
        const char expected = i < 2 ? ',' : '\0';
        if (end == p || *end != expected || !std::isfinite(c[i]) || c[i] < 0.0f)
            throw std::invalid_argument(option + ": '" + text +
                                        "' is not three non-negative numbers R,G,B");
        p = end + 1;
    }
    return c;
}

Options parse(int argc, char** argv) {
    Options o;
    o.settings.width = kCliSize;
    o.settings.height = kCliSize;
    o.settings.photons_per_pass = kCliPhotons;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
            return argv[++i];
        };
        auto number = [&]() {
            const std::string v = value();
            char* end = nullptr;
            const double x = std::strtod(v.c_str(), &end);
            if (end == v.c_str() || *end) throw std::invalid_argument(a + ": '" + v + "' is not a number");
            return x;
        };
        if (a == "--width") o.settings.width = static_cast<int>(number());
        else if (a == "--height") o.settings.height = static_cast<int>(number());
        else if (a == "--passes") o.passes = static_cast<int>(number());
        else if (a == "--seconds") o.seconds = number();
        else if (a == "--photons") o.settings.photons_per_pass = static_cast<std::uint32_t>(number());
        else if (a == "--alpha") o.settings.alpha = static_cast<float>(number());
        else if (a == "--radius") o.settings.initial_radius = static_cast<float>(number());
        else if (a == "--radius-scale") o.settings.radius_scale = static_cast<float>(number());
        else if (a == "--max-bounces" || a == "--max-depth") o.settings.max_bounces = static_cast<int>(number());
        else if (a == "--diffuse-bounces") o.settings.max_diffuse_bounces = static_cast<int>(number());
        else if (a == "--glossy-bounces") o.settings.max_glossy_bounces = static_cast<int>(number());
        else if (a == "--transmission-bounces")
            o.settings.max_transmission_bounces = static_cast<int>(number());
        else if (a == "--hash") o.settings.hash = parse_hash_mode(value());
        else if (a == "--rng") o.settings.rng = parse_rng_kind(value());
        else if (a == "--direct") o.settings.direct_light = parse_direct_light(value());
        else if (a == "--emitter-mis-fraction")
            o.settings.emitter_mis_fraction = static_cast<float>(number());
        else if (a == "--instancing") o.settings.instancing = parse_instancing(value());
        else if (a == "--device") {
            const std::vector<int> devices = gl::parse_device_list(value());
            o.settings.devices = devices.size() > 1 ? devices : std::vector<int>{};
            o.settings.device = devices[0];
        }
        else if (a == "--estimator") o.settings.estimator = parse_estimator(value());
        else if (a == "--vcm-techniques")
            o.settings.vcm_techniques = parse_vcm_techniques(value());
        else if (a == "--light-tracing") {
            const std::string v = value();
            if (v != "on" && v != "off")
                throw std::invalid_argument("--light-tracing: '" + v + "' is not on or off");
            o.settings.light_tracing = v == "on";
        }
        else if (a == "--first-pass") o.settings.first_pass = static_cast<std::uint64_t>(number());
        else if (a == "--seed") o.settings.seed = static_cast<std::uint64_t>(number());
        else if (a == "--max-block-bytes") o.settings.max_block_bytes = static_cast<std::uint64_t>(number());
        else if (a == "--out") o.out = value();
        else if (a == "--passes-out") {
            o.settings.passes = parse_render_pass_list(value());
            o.multilayer = true;
        }
        else if (a == "--json") o.json = true;
        else if (a == "--scene") o.scene_file = value();
        else if (a == "--light-groups") o.light_groups = static_cast<int>(number());
        else if (a == "--mtl-convention") o.scene_options.mtl = parse_mtl_convention(value());
        else if (a == "--environment") o.environment = value();
        else if (a == "--environment-color") {
            o.environment_color = parse_color(a, value());
            o.has_environment_color = true;
        }
        else if (a == "--help" || a == "-h") {
            std::fputs(usage().c_str(), stdout);
            std::exit(0);
        } else throw std::invalid_argument("unknown option " + a + " (see --help)");
    }
    if (o.passes <= 0 && o.seconds <= 0.0) o.passes = 64;
    validate(o.settings);
    return o;
}

// The scene to render; the loader's warnings are printed on stderr and kept for --json.
Scene build_scene(const Options& o, std::vector<std::string>& warnings) {
    Scene scene;
    if (o.scene_file.empty()) {
        scene = make_cornell_box();
    } else {
        LoadedScene loaded =
            load_scene_file(o.scene_file, float(o.settings.width) / float(o.settings.height),
                            o.scene_options);
        warnings = std::move(loaded.warnings);
        scene = std::move(loaded.scene);
    }
    if (!o.environment.empty()) {
        scene.textures.push_back(load_texture(o.environment));
        scene.environment_texture = static_cast<std::int32_t>(scene.textures.size() - 1);
        scene.environment = glm::vec3(1.0f);
    }
    if (o.has_environment_color) scene.environment = o.environment_color;
    if (o.light_groups > 0) assign_light_groups_round_robin(scene, o.light_groups);
    for (const std::string& w : warnings) std::fprintf(stderr, "glslppm-render: warning: %s\n", w.c_str());
    return scene;
}

// Each worker's device and passes per second.
nlohmann::json devices_json(const RenderStats& s) {
    nlohmann::json out = nlohmann::json::array();
    for (const DeviceStats& d : s.devices)
        out.push_back({{"device", d.device}, {"renderer", d.renderer}, {"passes", d.passes},
                       {"seconds", d.seconds}, {"passes_per_second", d.passes_per_second}});
    return out;
}

void progress(double fraction, const RenderStats& s) {
    const int width = 30;
    const int filled = static_cast<int>(fraction * width);
    std::fprintf(stderr, "\r[%.*s%*s] %3d%%  pass %llu  %.2f Mphotons/s", filled,
                 "##############################", width - filled, "",
                 static_cast<int>(100.0 * fraction), static_cast<unsigned long long>(s.passes),
                 s.photons_per_second * 1e-6);
    std::fflush(stderr);
}

}  // namespace

int main(int argc, char** argv) {
    try {
        const Options o = parse(argc, argv);
        std::vector<std::string> warnings;
        const Scene scene = build_scene(o, warnings);
        if (o.multilayer && o.out.empty())
            throw std::invalid_argument("--passes-out needs --out FILE.exr to write them to");
        const TilePlan plan = plan_tiles(scene, o.settings);
        std::vector<ExrPass> layers;  // --passes-out: Combined, then the passes
        const bool terminal = isatty(STDERR_FILENO);
        RenderStats s;
        std::vector<float> film;
        if (plan.tiles.size() > 1) {
            if (o.passes <= 0)
                throw std::invalid_argument("a " + std::to_string(o.settings.width) + "x" +
                                            std::to_string(o.settings.height) + " frame renders in " +
                                            std::to_string(plan.tiles.size()) +
                                            " tiles, each its own passes: give --passes");
            TiledImage image = render_tiled(
                scene, o.settings, o.passes, plan,
                [&](std::size_t index, const Tile& tile, const std::vector<float>&) {
                    std::fprintf(stderr, "tile %zu/%zu done (rows %d-%d)\n", index + 1,
                                 plan.tiles.size(), tile.y, tile.y + tile.height - 1);
                    return true;
                });
            s = image.stats;
            film = std::move(image.rgba);
            if (o.multilayer)
                layers = render_pass_layers(film, o.settings.passes, image.passes,
                                            scene.light_groups, image.light_groups);
        } else {
            Renderer renderer(scene, o.settings);
            const auto start = std::chrono::steady_clock::now();
            auto elapsed = [&] {
                return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            };
            int done = 0, step = 1;
            while (true) {
                if (o.passes > 0 && done >= o.passes) break;
                if (o.seconds > 0.0 && elapsed() >= o.seconds) break;
                int n = step;
                if (o.passes > 0) n = std::min(n, o.passes - done);
                const double before = elapsed();
                renderer.run(n);
                done += n;
                // Aim for about four progress updates a second.
                const double took = elapsed() - before;
                if (took < 0.125) step *= 2;
                else if (took > 0.5 && step > 1) step /= 2;
                if (terminal) {
                    const double f = o.passes > 0 ? double(done) / o.passes : elapsed() / o.seconds;
                    progress(std::min(1.0, f), renderer.stats());
                }
            }
            if (terminal) std::fputc('\n', stderr);
            s = renderer.stats();
            if (!o.out.empty()) film = renderer.film();
            if (o.multilayer)
                layers = render_pass_layers(film, o.settings.passes,
                                            renderer.render_passes(o.settings.passes),
                                            renderer.light_groups(),
                                            renderer.light_group_passes());
        }
        for (const std::string& w : s.warnings) {  // the renderer's own (downscaled images, ...)
            std::fprintf(stderr, "glslppm-render: warning: %s\n", w.c_str());
            warnings.push_back(w);
        }
        if (!o.out.empty()) {
            FloatImage image{o.settings.width, o.settings.height, std::move(film)};
            std::map<std::string, std::string> attributes = farm_attributes(o.settings, s);
            attributes.insert(
                      {{"passes", std::to_string(s.passes)},
                       {"photons_emitted", std::to_string(s.photons_emitted)},
                       {"seconds", std::to_string(s.seconds)},
                       {"photons_per_pass", std::to_string(o.settings.photons_per_pass)},
                       {"alpha", std::to_string(o.settings.alpha)},
                       {"initial_radius", std::to_string(s.initial_radius)},
                       {"hash", to_string(o.settings.hash)},
                       {"rng", to_string(o.settings.rng)},
                       {"direct_light", to_string(o.settings.direct_light)},
                       {"emitter_mis_fraction", std::to_string(o.settings.emitter_mis_fraction)},
                       {"max_bounces", std::to_string(o.settings.max_bounces)},
                       {"max_diffuse_bounces", std::to_string(o.settings.max_diffuse_bounces)},
                       {"max_glossy_bounces", std::to_string(o.settings.max_glossy_bounces)},
                       {"max_transmission_bounces",
                        std::to_string(o.settings.max_transmission_bounces)},
                       {"renderer", s.renderer},
                       {"variant", s.variant}});
            if (o.multilayer)
                write_multilayer_exr(o.out, image.width, image.height, layers, attributes);
            else
                write_exr(o.out, image, attributes);
        }
        if (o.json) {
            const nlohmann::json out = {
                {"passes", s.passes},
                {"photons_emitted", s.photons_emitted},
                {"seconds", s.seconds},
                {"passes_per_second", s.seconds > 0 ? s.passes / s.seconds : 0.0},
                {"photons_per_second", s.photons_per_second},
                {"rays_per_second", s.rays_per_second},
                {"width", o.settings.width},
                {"height", o.settings.height},
                {"photons_per_pass", o.settings.photons_per_pass},
                {"mean_radius", s.mean_radius},
                {"gpu_bytes", s.gpu_bytes},
                {"gpu_bytes_per_pixel", s.gpu_bytes_per_pixel},
                {"tiles", s.tiles},
                {"renderer", s.renderer},
                {"variant", s.variant},
                {"direct_light", s.direct_light},
                {"estimator", s.estimator},
                {"pass_ranges", format_pass_ranges(s.pass_ranges)},
                {"scene_hash", s.scene_hash},
                {"devices", devices_json(s)},
                {"instancing", s.instancing},
                {"instances", s.instances},
                {"instanced_triangles", s.instanced_triangles},
                {"warnings", warnings},
            };
            std::printf("%s\n", out.dump().c_str());
        } else {
            std::printf("%llu passes, %.3g photons in %.2f s: %.2f Mphotons/s, %.2f Mrays/s (%s)\n",
                        static_cast<unsigned long long>(s.passes), double(s.photons_emitted),
                        s.seconds, s.photons_per_second * 1e-6, s.rays_per_second * 1e-6,
                        s.renderer.c_str());
        }
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "glslppm-render: %s\n", e.what());
        return 1;
    }
}
