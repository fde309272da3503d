// glslppm-bench specialize: how much faster programs that model only what the scene uses
// run than the full variant (every feature compiled in) on the same scene and settings.
// The two renderers alternate in rounds so that drift in the machine's speed (thermal,
// other load) falls on both alike; the images are compared too (same seed: they agree).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/bench_scene.h"
#include "render/renderer.h"

using namespace glslppm;

int bench_specialization(int argc, char** argv) {
    RenderSettings settings;
    settings.width = settings.height = 512;
    settings.photons_per_pass = 262144;
    int passes = 32, rounds = 4;
    bool json = false;
    std::string scene_spec = "cornell-diffuse";
    for (int i = 0; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&] { return static_cast<double>(option_integer(a, argc, argv, i)); };
        if (parse_render_option(argc, argv, i, settings, scene_spec)) continue;
        if (a == "--passes") passes = static_cast<int>(next());
        else if (a == "--rounds") rounds = static_cast<int>(next());
        else if (a == "--json") json = true;
        else {
            std::fprintf(stderr, "glslppm-bench specialize: unknown option %s\n", a.c_str());
            return 2;
        }
    }
    try {
        const Scene scene = make_bench_scene(scene_spec, float(settings.width) / settings.height);
        RenderSettings full_settings = settings;
        full_settings.full_variant = true;
        Renderer specialized(scene, settings);
        Renderer full(scene, full_settings);
        specialized.run(2);  // warm-up, not timed
        full.run(2);
        double t_specialized = 0.0, t_full = 0.0;
        for (int r = 0; r < rounds; ++r) {
            const double s0 = specialized.stats().seconds;
            specialized.run(passes);
            t_specialized += specialized.stats().seconds - s0;
            const double f0 = full.stats().seconds;
            full.run(passes);
            t_full += full.stats().seconds - f0;
        }
        const std::vector<float> a = specialized.film(), b = full.film();
        double largest = 0.0, difference = 0.0;
        for (std::size_t i = 0; i < a.size(); ++i) {
            largest = std::max(largest, double(std::abs(a[i])));
            difference = std::max(difference, double(std::abs(a[i] - b[i])));
        }
        const RenderStats st = specialized.stats(), ft = full.stats();
        const double total = double(passes) * rounds;
        const double ratio = t_full / t_specialized;
        if (json) {
            const nlohmann::json out = {
                {"bench", "specialize"},
                {"scene", scene_spec},
                {"width", settings.width},
                {"height", settings.height},
                {"photons_per_pass", settings.photons_per_pass},
                {"passes", total},
                {"renderer", st.renderer},
                {"specialized_variant", st.variant},
                {"full_variant", ft.variant},
                {"specialized_passes_per_second", total / t_specialized},
                {"full_passes_per_second", total / t_full},
                {"speedup", ratio},
                {"max_image_difference_relative", largest > 0 ? difference / largest : 0.0},
            };
            std::printf("%s\n", out.dump().c_str());
        } else {
            std::printf("scene %s, %dx%d, %u photons/pass, %.0f passes each, on %s\n",
                        scene_spec.c_str(), settings.width, settings.height,
                        settings.photons_per_pass, total, st.renderer.c_str());
            std::printf("  specialized (%s): %.2f passes/s\n", st.variant.c_str(),
                        total / t_specialized);
            std::printf("  full        (%s): %.2f passes/s\n", ft.variant.c_str(), total / t_full);
            std::printf("  speed-up %.3fx; images differ by at most %.3g of the brightest pixel\n",
                        ratio, largest > 0 ? difference / largest : 0.0);
        }
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "glslppm-bench specialize: %s\n", e.what());
        return 1;
    }
}
