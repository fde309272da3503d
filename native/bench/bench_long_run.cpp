// glslppm-bench longrun: the long run (tests/long/long_run.py in C++, for
// machines without the Python module). Inside a closed box whose walls emit Le = 1 and
// reflect a = 0.5, with one bounce (max depth 1) every pixel sees Le + a Le = 1.5 exactly and
// every photon path ends after one bounce, so the photons emitted must be passes x photons
// per pass exactly; 21,504 photons per pass take that past 2^32 in 200,000 passes. At
// log-spaced checkpoints: the film is finite, the counts exact, the radii never grow, and the
// rms error against 1.5 keeps falling (log-log slope over the last two decades below -0.2).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/bench_scene.h"
#include "render/renderer.h"

using namespace glslppm;

int bench_long_run(int argc, char** argv) {
    RenderSettings settings;
    settings.width = settings.height = 8;
    settings.photons_per_pass = 21504;
    settings.max_bounces = 0;  // direct light only: one photon per path, so one per pass
    settings.seed = 1;
    long long total = 200000;
    for (int i = 0; i < argc; ++i) {
        const std::string a = argv[i];
        auto next = [&] { return static_cast<double>(option_integer(a, argc, argv, i)); };
        if (a == "--passes") total = static_cast<long long>(next());
        else if (a == "--photons") settings.photons_per_pass = static_cast<std::uint32_t>(next());
        else if (a == "--width") settings.width = settings.height = static_cast<int>(next());
        else if (a == "--seed") settings.seed = static_cast<std::uint64_t>(next());
        else if (a == "--device") settings.device = static_cast<int>(next());
        else if (a == "--json") continue;  // the output is JSON anyway
        else {
            std::fprintf(stderr, "glslppm-bench longrun: unknown option %s\n", a.c_str());
            return 2;
        }
    }
    try {
        Renderer renderer(make_bench_scene("furnace"), settings);
        std::vector<long long> checkpoints;
        for (int i = 0;; ++i) {
            const long long k = std::llround(100.0 * std::pow(10.0, i / 4.0));
            if (k >= total) break;
            checkpoints.push_back(k);
        }
        checkpoints.push_back(total);
        const double exact = furnace_radiance(settings.max_bounces);
        std::vector<std::string> failures;
        std::vector<double> log_k, log_e;
        nlohmann::json rows = nlohmann::json::array();
        RenderStats previous = renderer.stats();
        long long done = 0;
        for (long long k : checkpoints) {
            while (done < k) done += renderer.run(static_cast<int>(std::min(k - done, 10000LL)));
            const std::vector<float> film = renderer.film();
            const RenderStats s = renderer.stats();
            bool finite = true;
            double sum2 = 0.0;
            std::size_t n = 0;
            for (std::size_t p = 0; p < film.size(); p += 4) {
                for (int c = 0; c < 3; ++c) {
                    finite &= std::isfinite(film[p + c]);
                    sum2 += (film[p + c] - exact) * (film[p + c] - exact);
                    ++n;
                }
            }
            const double error = std::sqrt(sum2 / double(n));
            const std::string at = " after " + std::to_string(k) + " passes";
            if (!finite) failures.push_back("film not finite" + at);
            if (s.passes != std::uint64_t(k)) failures.push_back("pass count wrong" + at);
            if (s.photons_emitted != std::uint64_t(k) * settings.photons_per_pass)
                failures.push_back("photons_emitted " + std::to_string(s.photons_emitted) +
                                   " != passes x photons" + at);
            if (s.mean_radius > previous.mean_radius || s.max_radius > previous.max_radius)
                failures.push_back("radius grew" + at);
            previous = s;
            if (double(k) >= double(total) / 100.0 && finite && error > 0) {
                log_k.push_back(std::log10(double(k)));
                log_e.push_back(std::log10(error));
            }
            rows.push_back({{"passes", s.passes},
                            {"photons_emitted", s.photons_emitted},
                            {"rms_error", error},
                            {"mean_radius", s.mean_radius},
                            {"max_radius", s.max_radius},
                            {"seconds", s.seconds}});
        }
        // Least-squares slope of log error against log passes over the last two decades.
        double slope = NAN;
        if (log_k.size() > 2) {
            double mk = 0, me = 0;
            for (std::size_t i = 0; i < log_k.size(); ++i) mk += log_k[i], me += log_e[i];
            mk /= log_k.size();
            me /= log_e.size();
            double sxy = 0, sxx = 0;
            for (std::size_t i = 0; i < log_k.size(); ++i) {
                sxy += (log_k[i] - mk) * (log_e[i] - me);
                sxx += (log_k[i] - mk) * (log_k[i] - mk);
            }
            slope = sxy / sxx;
        }
        if (!(slope < -0.2)) failures.push_back("error slope over the last two decades >= -0.2");
        const RenderStats s = renderer.stats();
        // A slope that cannot be measured (too few checkpoints) is written as null.
        const nlohmann::json out = {
            {"bench", "longrun"},
            {"renderer", s.renderer},
            {"passes", s.passes},
            {"photons_per_pass", settings.photons_per_pass},
            {"photons_emitted", s.photons_emitted},
            {"past_2_32", s.photons_emitted > (1ull << 32)},
            {"seconds", s.seconds},
            {"initial_radius", s.initial_radius},
            {"error_slope_last_two_decades", slope},
            {"checkpoints", rows},
            {"failures", failures},
            {"ok", failures.empty()}};
        std::printf("%s\n", out.dump().c_str());
        return failures.empty() ? 0 : 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "glslppm-bench longrun: %s\n", e.what());
        return 1;
    }
}
