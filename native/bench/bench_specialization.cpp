// glslppm-bench specialize: how much faster programs that model only what the scene uses
// run than the full variant (every feature compiled in) on the same scene and settings.
// The two renderers alternate in rounds so that drift in the machine's speed (thermal,
// other load) falls on both alike; the images are compared too (same seed: they agree).
//
// glslppm-bench specialize --each: each row of render/specializations.h that the scene does
// not need, forced alone into its programs (RenderSettings::forced_features), against the
// scene's own programs: the row's gain, what compiling it only where needed saves. One line
// (or JSON object) per row.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bench/bench_scene.h"
#include "render/renderer.h"
#include "render/specializations.h"

using namespace glslppm;

namespace {

// Seconds of `passes` passes on r.
double timed(Renderer& r, int passes) {
    const double s0 = r.stats().seconds;
    r.run(passes);
    return r.stats().seconds - s0;
}

int each_row(const Scene& scene, const RenderSettings& settings, const std::string& scene_spec,
             int passes, int rounds, bool json) {
    std::string base_variant, renderer;
    {
        Renderer probe(scene, settings);
        base_variant = probe.stats().variant;
        renderer = probe.stats().renderer;
    }
    if (!json)
        std::printf("scene %s, %dx%d, %u photons/pass, %d x %d passes, on %s\n  its variant: %s\n",
                    scene_spec.c_str(), settings.width, settings.height, settings.photons_per_pass,
                    rounds, passes, renderer.c_str(), base_variant.c_str());
    // First a control: the scene's own programs against themselves (the bench's own spread).
    std::vector<const Specialization*> rows{nullptr};
    for (const Specialization& row : specializations()) rows.push_back(&row);
    for (const Specialization* row : rows) {
        RenderSettings forced_settings = settings;
        if (row != nullptr) forced_settings.forced_features = {row->name};
        Renderer forced(scene, forced_settings);
        // Needed here, or not applicable.
        if (row != nullptr && forced.stats().variant == base_variant) continue;
        // A fresh renderer of the scene's own programs beside it: SPPM's passes grow cheaper
        // as the radii shrink, so both must be at the same pass.
        Renderer base(scene, settings);
        base.run(2);
        forced.run(2);
        double t_base = 0.0, t_forced = 0.0;
        // Which runs first alternates (A B B A ...): the first of a pair measured up to 3%
        // apart from the second with the same programs on the H100.
        for (int r = 0; r < rounds; ++r) {
            if (r % 2 == 0) {
                t_base += timed(base, passes);
                t_forced += timed(forced, passes);
            } else {
                t_forced += timed(forced, passes);
                t_base += timed(base, passes);
            }
        }
        const double total = double(passes) * rounds;
        const double gain = t_forced / t_base - 1.0;  // the pass time the row would add
        if (json) {
            const nlohmann::json out = {{"bench", "specialize-each"},
                                        {"scene", scene_spec},
                                        {"width", settings.width},
                                        {"height", settings.height},
                                        {"row", row ? row->name : "(control)"},
                                        {"define", row ? row->define : ""},
                                        {"base_passes_per_second", total / t_base},
                                        {"forced_passes_per_second", total / t_forced},
                                        {"gain", gain},
                                        {"renderer", renderer}};
            std::printf("%s\n", out.dump().c_str());
        } else {
            std::printf("  %-20s %-24s %9.2f -> %9.2f passes/s: leaving it out saves %+.2f%%\n",
                        row ? row->name : "(control)", row ? row->define : "(the same)",
                        total / t_base, total / t_forced, 100.0 * gain);
        }
        std::fflush(stdout);
    }
    return 0;
}

}  // namespace

int bench_specialization(int argc, char** argv) {
    RenderSettings settings;
    settings.width = settings.height = 512;
    settings.photons_per_pass = 262144;
    int passes = 32, rounds = 4;
    bool json = false, each = false;
    std::string scene_spec = "cornell-diffuse";
    for (int i = 0; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&] { return static_cast<double>(option_integer(a, argc, argv, i)); };
        if (parse_render_option(argc, argv, i, settings, scene_spec)) continue;
        if (a == "--passes")
            passes = static_cast<int>(next());
        else if (a == "--rounds")
            rounds = static_cast<int>(next());
        else if (a == "--json")
            json = true;
        else if (a == "--each")
            each = true;
        else {
            std::fprintf(stderr, "glslppm-bench specialize: unknown option %s\n", a.c_str());
            return 2;
        }
    }
    try {
        const Scene scene = make_bench_scene(scene_spec, float(settings.width) / settings.height);
        if (each) return each_row(scene, settings, scene_spec, passes, rounds, json);
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
