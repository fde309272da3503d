// glslppm-bench passes: end-to-end throughput (SPPM or PPPM, one or several devices) on a benchmark scene (--scene, default the
// built-in Cornell box).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "bench/bench_scene.h"
#include "render/renderer.h"
#include "scene/light_groups.h"

using namespace glslppm;

int bench_passes(int argc, char** argv) {
    RenderSettings settings;
    settings.width = settings.height = 512;
    settings.photons_per_pass = 262144;
    int passes = 64, warmup = 4;
    bool json = false;
    // Several devices (PPPM): also run the same passes on the first device alone, and
    // report its passes/s (the scaling) and how far the merged film is from its film.
    bool against_one_device = false;
    std::string scene_spec = "cornell";
    int light_groups = 0;
    for (int i = 0; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&] { return static_cast<double>(option_integer(a, argc, argv, i)); };
        if (parse_render_option(argc, argv, i, settings, scene_spec)) continue;
        if (a == "--passes") passes = static_cast<int>(next());
        // Render passes beside Combined (docs/passes.md): what they cost.
        else if (a == "--render-passes" && i + 1 < argc)
            settings.passes = parse_render_pass_list(argv[++i]);
        else if (a == "--warmup") warmup = static_cast<int>(next());
        // Light groups (docs/light_groups.md): the scene's emitters dealt into N groups.
        else if (a == "--light-groups") light_groups = static_cast<int>(next());
        else if (a == "--json") json = true;
        else if (a == "--against-one-device") against_one_device = true;
        else {
            std::fprintf(stderr, "glslppm-bench passes: unknown option %s\n", a.c_str());
            return 2;
        }
    }
    try {
        const float aspect = float(settings.width) / float(settings.height);
        const auto setup_start = std::chrono::steady_clock::now();
        Scene scene = make_bench_scene(scene_spec, aspect);
        if (light_groups > 0) assign_light_groups_round_robin(scene, light_groups);
        Renderer renderer(scene, settings);
        // Scene generation, validation, BVH build, GL set-up and compiles.
        const double setup_seconds = std::chrono::duration<double>(
                                         std::chrono::steady_clock::now() - setup_start)
                                         .count();
        renderer.run(warmup);  // compiles lazily on some drivers; not timed
        const RenderStats before = renderer.stats();
        renderer.run(passes);
        const RenderStats after = renderer.stats();
        const double seconds = after.seconds - before.seconds;
        // The film read back (resolve and copy to the host) into one buffer, as the add-on's
        // progressive updates and viewport redraws read it: the fastest of three.
        double film_seconds = 0.0;
        std::vector<float> film(std::size_t(settings.width) * std::size_t(settings.height) * 4);
        for (int k = 0; k < 3; ++k) {
            const auto read_start = std::chrono::steady_clock::now();
            renderer.film_into(film);
            const double t = std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                                           read_start).count();
            film_seconds = k == 0 ? t : std::min(film_seconds, t);
        }
        const double photons = double(after.photons_emitted - before.photons_emitted);
        const double rays = double(after.rays - before.rays);
        // Stage times come from a second, profiled renderer: timer queries wait every pass.
        // VCM has no profile yet (docs/vcm.md): its stage times stay null.
        const bool profiles = settings.estimator != Estimator::Vcm;
        RenderStats st{};
        const int profiled_passes = std::max(1, std::min(passes, 16));
        if (profiles) {
            RenderSettings profiled = settings;
            profiled.profile = true;
            Renderer timed(scene, profiled);
            timed.run(profiled_passes);
            st = timed.stats();
        }
        const double ms = 1e3 / profiled_passes;
        // Each worker's passes and passes per second over the timed passes alone.
        nlohmann::json devices = nlohmann::json::array();
        for (std::size_t k = 0; k < after.devices.size(); ++k) {
            const DeviceStats& a = after.devices[k];
            const DeviceStats& b = before.devices[k];
            const double t = a.seconds - b.seconds;
            devices.push_back({{"device", a.device},
                               {"renderer", a.renderer},
                               {"passes", a.passes - b.passes},
                               {"seconds", t},
                               {"submit_seconds", a.submit_seconds - b.submit_seconds},
                               {"wait_seconds", a.wait_seconds - b.wait_seconds},
                               {"passes_per_second", t > 0 ? double(a.passes - b.passes) / t : 0.0}});
        }
        nlohmann::json one_device = nullptr;
        if (against_one_device) {
            if (settings.devices.size() < 2)
                throw std::invalid_argument("--against-one-device needs several devices (--device 0,1)");
            RenderSettings alone = settings;
            alone.devices = {settings.devices[0]};
            Renderer single(scene, alone);
            single.run(warmup);
            const RenderStats b = single.stats();
            single.run(passes);
            const RenderStats a = single.stats();
            const double t = a.seconds - b.seconds;
            // The same pass indices (PPPM deals 0 .. warmup + passes - 1 either way): the
            // merged film differs from this one only by float rounding in the merge.
            const std::vector<float> merged = renderer.film(), reference = single.film();
            double largest = 0.0, largest_relative = 0.0;
            for (std::size_t i = 0; i < merged.size(); ++i) {
                const double d = std::abs(double(merged[i]) - double(reference[i]));
                const double m = std::max(std::abs(double(merged[i])), std::abs(double(reference[i])));
                largest = std::max(largest, d);
                if (m > 0) largest_relative = std::max(largest_relative, d / m);
            }
            one_device = {{"device", alone.devices[0]},
                          {"passes_per_second", t > 0 ? passes / t : 0.0},
                          {"speedup", t > 0 ? (passes / seconds) / (passes / t) : 0.0},
                          {"max_difference", largest},
                          {"max_difference_relative", largest_relative}};
        }
        if (json) {
            const nlohmann::json out = {
                {"bench", "passes"},
                {"scene", scene_spec},
                {"width", settings.width},
                {"height", settings.height},
                {"photons_per_pass", settings.photons_per_pass},
                {"hash", to_string(settings.hash)},
                {"rng", to_string(settings.rng)},
                {"direct_light", to_string(settings.direct_light)},
                {"glossy_threshold", settings.glossy_threshold},
                {"emitter_mis_fraction", settings.emitter_mis_fraction},
                {"estimator", to_string(settings.estimator)},
                {"light_tracing", settings.light_tracing},
                {"max_bounces", settings.max_bounces},
                {"passes", passes},
                {"seconds", seconds},
                {"passes_per_second", passes / seconds},
                {"photons_per_second", photons / seconds},
                {"rays_per_second", rays / seconds},
                {"photon_bounces_per_second",
                 passes * double(settings.photons_per_pass) / seconds},
                {"vcm_techniques", to_string(settings.vcm_techniques)},
                {"stage_ms", profiles ? nlohmann::json{{"eye", st.eye_seconds * ms},
                                                       {"photon", st.photon_seconds * ms},
                                                       {"hash", st.hash_seconds * ms},
                                                       {"gather", st.gather_seconds * ms}}
                                      : nlohmann::json(nullptr)},
                {"triangles", after.triangles},
                {"instancing", after.instancing},
                {"instancing_reason", after.instancing_reason},
                {"instances", after.instances},
                {"instanced_triangles", after.instanced_triangles},
                // Motion blur (--scene S+motion): what moves and the host's refit per pass.
                {"motion", after.motion},
                {"moving_instances", after.moving_instances},
                {"motion_refit_ms_per_pass",
                 after.passes ? 1e3 * after.motion_refit_seconds / double(after.passes) : 0.0},
                {"gpu_bytes", after.gpu_bytes},
                {"gpu_bytes_per_pixel", after.gpu_bytes_per_pixel},
                {"gpu_bytes_per_photon", after.gpu_bytes_per_photon},
                {"bvh_seconds", after.bvh_seconds},
                {"bvh_bytes_per_triangle", after.bvh_bytes_per_triangle},
                {"setup_seconds", setup_seconds},
                {"film_read_seconds", film_seconds},
                {"renderer", after.renderer},
                {"variant", after.variant},
                {"gpu_bytes_per_pixel", after.gpu_bytes_per_pixel},
                {"devices", devices},
                {"one_device", one_device},
            };
            std::printf("%s\n", out.dump().c_str());
        } else {
            std::printf("%s: %dx%d, %u photons/pass, %s hash, %s rng, %s direct light\n",
                        after.renderer.c_str(),
                        settings.width, settings.height, settings.photons_per_pass,
                        to_string(settings.hash).c_str(), to_string(settings.rng).c_str(),
                        to_string(settings.direct_light).c_str());
            std::printf("  instancing %s (%s): %zu instances, %zu instanced triangles, %zu "
                        "distinct; BVH %.3f s, GPU %zu bytes, set-up %.2f s, film read %.1f ms\n",
                        after.instancing.c_str(), after.instancing_reason.c_str(),
                        after.instances, after.instanced_triangles, after.triangles,
                        after.bvh_seconds, after.gpu_bytes, setup_seconds, film_seconds * 1e3);
            if (after.motion != "none")
                std::printf("  motion: %s, %zu moving instances, refit %.3f ms/pass (host)\n",
                            after.motion.c_str(), after.moving_instances,
                            after.passes ? 1e3 * after.motion_refit_seconds / double(after.passes)
                                         : 0.0);
            std::printf("  %.2f passes/s  %.3f Mphotons/s  %.2f Mrays/s (%s)\n", passes / seconds,
                        photons / seconds * 1e-6, rays / seconds * 1e-6,
                        to_string(settings.estimator).c_str());
            for (const auto& d : devices)
                std::printf("  device %d: %llu passes, %.2f passes/s\n", d["device"].get<int>(),
                            d["passes"].get<unsigned long long>(),
                            d["passes_per_second"].get<double>());
            if (!one_device.is_null())
                std::printf("  device %d alone: %.2f passes/s, speed-up %.3fx; films differ by at "
                            "most %.3g (relative %.3g)\n",
                            one_device["device"].get<int>(),
                            one_device["passes_per_second"].get<double>(),
                            one_device["speedup"].get<double>(),
                            one_device["max_difference"].get<double>(),
                            one_device["max_difference_relative"].get<double>());
            std::printf("  per pass: eye %.3f ms, photon %.3f ms, hash %.3f ms, gather %.3f ms\n",
                        st.eye_seconds * ms, st.photon_seconds * ms, st.hash_seconds * ms,
                        st.gather_seconds * ms);
        }
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "glslppm-bench passes: %s\n", e.what());
        return 1;
    }
}
