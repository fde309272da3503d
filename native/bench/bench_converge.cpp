// glslppm-bench converge: the error of the image against a reference as a function of
// passes and of wall time, for a list of settings (the Cartesian product of the --alpha,
// --photons, --radius-scale, --hash, --rng and --direct lists). Errors are RMSE and relative MSE
// (mean of (x - r)^2 / (r^2 + 0.01) over pixels and RGB), measured at passes 1, 2, 4, ...;
// the slope of log MSE against log passes is fitted by least squares and printed beside the
// theoretical one: with radius R^2 ~ N^(alpha - 1), bias^2 ~ N^(2 (alpha - 1)) and variance
// ~ N^-alpha (Knaus and Zwicker 2011), MSE ~ N^-min(alpha, 2 (1 - alpha)), best (-2/3) at
// alpha = 2/3 (Kaplanyan and Dachsbacher 2013).
//
// The reference is a long run of the same scene with exact hashing (and the default
// direct light: light sampling has no kernel blur on direct light to bias it), written as EXR with
// its settings in glslppm/ attributes and reused when those match; --reference may also name an EXR
// made elsewhere (scripts/cycles_reference.py), and --cross-check a second reference that the first
// is compared with. A reference made by this renderer shares its biases, so a run can converge to
// the wrong answer and still pass; for `--scene furnace` the reference is instead the exact answer
// (furnace_radiance), and each point also reports the signed relative error of the image's mean
// (mean_bias), which noise averages out of and a bias does not.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "bench/bench_scene.h"
#include "image/exr.h"
#include "render/renderer.h"

using namespace glslppm;
namespace fs = std::filesystem;

namespace {

struct ConvergeOptions {
    std::string scene = "cornell";
    int width = 64, height = 64;
    int passes = 64;
    int fit_from = 8;  // checkpoints with fewer passes are left out of the slope fit
    std::vector<float> alphas = {0.7f};
    std::vector<std::uint32_t> photons = {65536};
    std::vector<float> radius_scales = {1.0f};
    std::vector<HashMode> hashes = {HashMode::Stochastic};
    std::vector<RngKind> rngs = {RngKind::Pcg};
    std::vector<DirectLight> directs = {RenderSettings{}.direct_light};
    std::vector<Estimator> estimators = {RenderSettings{}.estimator};
    std::vector<float> glossy_thresholds = {RenderSettings{}.glossy_threshold};
    std::string reference;  // default: references/ beside the binary
    int reference_passes = 1024;
    std::uint32_t reference_photons = 65536;
    // The reference's initial radius over the automatic one: a smaller radius trades noise
    // for less of SPPM's finite-radius bias (darkened corners) at a given photon count.
    float reference_radius_scale = 1.0f;
    std::string cross_check;
    int device = -1;
    bool json = false;
};

struct ImageError {
    double rmse = 0.0, rel_mse = 0.0;
    double mean_bias = 0.0;  // sum(x) / sum(r) - 1 over pixels and RGB
};

struct Point {
    int passes = 0;
    double seconds = 0.0;
    ImageError error;
};

struct Run {
    RenderSettings settings;
    float radius_scale = 1.0f;
    std::vector<Point> points;
    double slope = 0.0;
};

struct Reference {
    FloatImage image;
    std::string path, source;  // source "analytic": no file, every pixel = value
    double value = 0.0;
    long passes = 0;
    bool created = false;
    double seconds = 0.0;
};

ImageError image_error(const std::vector<float>& rgba, const FloatImage& reference) {
    ImageError e;
    const std::size_t pixels = rgba.size() / 4;
    double se = 0.0, rel = 0.0, sum_x = 0.0, sum_r = 0.0;
    for (std::size_t p = 0; p < pixels; ++p) {
        for (int c = 0; c < 3; ++c) {
            const double x = rgba[4 * p + c], r = reference.rgba[4 * p + c];
            se += (x - r) * (x - r);
            rel += (x - r) * (x - r) / (r * r + 0.01);
            sum_x += x;
            sum_r += r;
        }
    }
    e.rmse = std::sqrt(se / double(3 * pixels));
    e.rel_mse = rel / double(3 * pixels);
    e.mean_bias = sum_r > 0.0 ? sum_x / sum_r - 1.0 : 0.0;
    return e;
}

// Least-squares slope of log(MSE) against log(passes) over the points from `fit_from` on.
// sum(a) / sum(b) - 1 over each cell of a kRegionGrid x kRegionGrid grid (row 0 at the
// image's first row): the cross-check's local bound, which a bias confined to one part of
// the image (a wall, the light's surroundings) cannot hide in the whole image's mean.
constexpr int kRegionGrid = 4;
std::vector<double> region_bias(const std::vector<float>& a, const FloatImage& b) {
    std::vector<double> sum_a(kRegionGrid * kRegionGrid), sum_b(sum_a.size());
    for (int y = 0; y < b.height; ++y)
        for (int x = 0; x < b.width; ++x) {
            const int cell = (y * kRegionGrid / b.height) * kRegionGrid + x * kRegionGrid / b.width;
            const std::size_t p = std::size_t(4) * (std::size_t(y) * b.width + x);
            for (int c = 0; c < 3; ++c) {
                sum_a[cell] += a[p + c];
                sum_b[cell] += b.rgba[p + c];
            }
        }
    std::vector<double> out(sum_a.size());
    for (std::size_t k = 0; k < out.size(); ++k)
        out[k] = sum_b[k] > 0.0 ? sum_a[k] / sum_b[k] - 1.0 : 0.0;
    return out;
}

double fitted_slope(const std::vector<Point>& points, int fit_from) {
    double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (const Point& p : points) {
        if (p.passes < fit_from || !(p.error.rmse > 0.0)) continue;
        const double x = std::log(double(p.passes)), y = std::log(p.error.rmse * p.error.rmse);
        n += 1, sx += x, sy += y, sxx += x * x, sxy += x * y;
    }
    const double d = n * sxx - sx * sx;
    return n >= 2 && d > 0 ? (n * sxy - sx * sy) / d : 0.0;
}

double theoretical_slope(double alpha) { return -std::min(alpha, 2.0 * (1.0 - alpha)); }

std::string number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.6g", v);
    return text;
}

// <folder of this binary>/references/<scene>_<W>x<H>.exr (the build folder's, on Linux;
// the current folder's where /proc is missing).
std::string default_reference_path(const ConvergeOptions& o) {
    const fs::path folder =
        fs::exists("/proc/self/exe") ? fs::read_symlink("/proc/self/exe").parent_path() : ".";
    std::string name = o.scene;
    for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return (folder / "references" /
            (name + "_" + std::to_string(o.width) + "x" + std::to_string(o.height) + ".exr"))
        .string();
}

// Loads the reference, checking that it was made for this scene and size (and, for one of
// ours, with at least the passes asked for); renders and writes it when the file is missing.
Reference load_or_make_reference(const ConvergeOptions& o, const Scene& scene,
                                 double automatic_radius) {
    Reference ref;
    ref.path = o.reference;
    if (ref.path.empty() && o.scene == "furnace") {
        ref.source = "analytic";
        ref.value = furnace_radiance(RenderSettings{}.max_bounces);
        ref.image = FloatImage{
            o.width, o.height,
            std::vector<float>(std::size_t(4) * o.width * o.height, static_cast<float>(ref.value))};
        return ref;
    }
    if (fs::exists(ref.path)) {
        std::map<std::string, std::string> a;
        ref.image = read_exr(ref.path, &a);
        ref.source = a.count("source") ? a["source"] : "unknown";
        ref.passes = a.count("passes") ? std::atol(a["passes"].c_str()) : 0;
        auto mismatch = [&](const std::string& what, const std::string& want) {
            throw std::invalid_argument("reference " + ref.path + " was made with " + what + " " +
                                        (a.count(what) ? a[what] : "(unset)") + ", not " + want +
                                        ": delete it to render a new one, or pass --reference");
        };
        if (ref.image.width != o.width || ref.image.height != o.height)
            throw std::invalid_argument("reference " + ref.path + " is " +
                                        std::to_string(ref.image.width) + "x" +
                                        std::to_string(ref.image.height) + ", the run " +
                                        std::to_string(o.width) + "x" + std::to_string(o.height));
        if (ref.source == "glslppm") {
            if (a["scene"] != o.scene) mismatch("scene", o.scene);
            if (a["hash"] != "exact") mismatch("hash", "exact");
            // References made before light sampling existed rendered direct light by photons.
            const std::string direct = a.count("direct_light") ? a["direct_light"] : "photons";
            if (direct != to_string(RenderSettings{}.direct_light))
                mismatch("direct_light", to_string(RenderSettings{}.direct_light));
            if (ref.passes < o.reference_passes)
                mismatch("passes", "at least " + std::to_string(o.reference_passes));
            const std::string scale = a.count("radius_scale") ? a["radius_scale"] : "1";
            if (scale != number(o.reference_radius_scale))
                mismatch("radius_scale", number(o.reference_radius_scale));
        }
        return ref;
    }
    RenderSettings s;
    s.width = o.width;
    s.height = o.height;
    s.photons_per_pass = o.reference_photons;
    if (o.reference_radius_scale != 1.0f)  // else automatic, as references made before
        s.initial_radius = static_cast<float>(o.reference_radius_scale * automatic_radius);
    s.hash = HashMode::Exact;
    s.seed = 987654321;  // independent of the runs measured against it (seeds 0..)
    s.device = o.device;
    Renderer renderer(scene, s);
    for (int done = 0; done < o.reference_passes;) {
        const int step = std::min(256, o.reference_passes - done);
        renderer.run(step);
        done += step;
    }
    const RenderStats st = renderer.stats();
    ref.image = FloatImage{o.width, o.height, renderer.film()};
    ref.source = "glslppm";
    ref.passes = o.reference_passes;
    ref.created = true;
    ref.seconds = st.seconds;
    fs::create_directories(fs::absolute(ref.path).parent_path());
    write_exr(ref.path, ref.image,
              {{"source", "glslppm"},
               {"scene", o.scene},
               {"hash", "exact"},
               {"passes", std::to_string(o.reference_passes)},
               {"photons_per_pass", std::to_string(s.photons_per_pass)},
               {"radius_scale", number(o.reference_radius_scale)},
               {"photons_emitted", std::to_string(st.photons_emitted)},
               {"alpha", number(s.alpha)},
               {"rng", to_string(s.rng)},
               {"direct_light", to_string(s.direct_light)},
               {"seed", std::to_string(s.seed)},
               {"seconds", number(st.seconds)},
               {"renderer", st.renderer}});
    return ref;
}

Run converge_run(const Scene& scene, const RenderSettings& settings, float radius_scale,
                 const ConvergeOptions& o, const FloatImage& reference) {
    Run run{settings, radius_scale, {}, 0.0};
    Renderer renderer(scene, settings);
    int done = 0;
    for (int next = 1;; next = std::min(2 * next, o.passes)) {
        renderer.run(next - done);
        done = next;
        run.points.push_back(
            {done, renderer.stats().seconds, image_error(renderer.film(), reference)});
        if (done == o.passes) break;
    }
    run.slope = fitted_slope(run.points, o.fit_from);
    return run;
}

template <class T, class F>
std::vector<T> parse_list(const std::string& text, F parse) {
    std::vector<T> out;
    std::size_t start = 0;
    while (start <= text.size()) {
        const std::size_t end = std::min(text.find(',', start), text.size());
        if (end > start) out.push_back(parse(text.substr(start, end - start)));
        start = end + 1;
    }
    if (out.empty()) throw std::invalid_argument("empty list '" + text + "'");
    return out;
}

float parse_float(const std::string& s) {
    std::size_t used = 0;
    const float v = std::stof(s, &used);
    if (used != s.size()) throw std::invalid_argument("'" + s + "' is not a number");
    return v;
}

// "2/3" as well as 0.6667 (the optimal alpha).
float parse_alpha(const std::string& s) {
    const std::size_t slash = s.find('/');
    if (slash == std::string::npos) return parse_float(s);
    return parse_float(s.substr(0, slash)) / parse_float(s.substr(slash + 1));
}

int usage() {
    std::fprintf(
        stderr,
        "usage: glslppm-bench converge [--scene S] [--width W --height H] [--passes K]\n"
        "       [--alpha 0.5,2/3,0.7,0.9] [--photons 65536,...] [--radius-scale 0.25,1,4]\n"
        "       [--hash stochastic,exact] [--rng paper,pcg] [--direct sampled,sampled-no-mis,photons]\n"
        "       [--estimator sppm,pppm]\n"
        "       [--glossy-threshold 0,0.2,0.5] (roughness below which lobes are followed)\n"
        "       [--fit-from P]\n"
        "       [--reference X.exr] [--reference-passes R] [--reference-photons N]\n"
        "       [--reference-radius-scale s]\n"
        "       [--cross-check Y.exr] [--device D] [--json]\n");
    return 2;
}

bool parse(int argc, char** argv, ConvergeOptions& o) {
    for (int i = 0; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--json") {
            o.json = true;
            continue;
        }
        if (i + 1 >= argc) return false;
        const std::string v = argv[++i];
        if (a == "--scene")
            o.scene = v;
        else if (a == "--width")
            o.width = static_cast<int>(parse_integer(a, v));
        else if (a == "--height")
            o.height = static_cast<int>(parse_integer(a, v));
        else if (a == "--size")
            o.width = o.height = static_cast<int>(parse_integer(a, v));
        else if (a == "--passes")
            o.passes = static_cast<int>(parse_count(v));
        else if (a == "--fit-from")
            o.fit_from = static_cast<int>(parse_integer(a, v));
        else if (a == "--alpha")
            o.alphas = parse_list<float>(v, parse_alpha);
        else if (a == "--photons")
            o.photons = parse_list<std::uint32_t>(
                v, [](const std::string& s) { return static_cast<std::uint32_t>(parse_count(s)); });
        else if (a == "--radius-scale")
            o.radius_scales = parse_list<float>(v, parse_float);
        else if (a == "--hash")
            o.hashes = parse_list<HashMode>(v, parse_hash_mode);
        else if (a == "--rng")
            o.rngs = parse_list<RngKind>(v, parse_rng_kind);
        else if (a == "--direct")
            o.directs = parse_list<DirectLight>(v, parse_direct_light);
        else if (a == "--estimator")
            o.estimators = parse_list<Estimator>(v, parse_estimator);
        else if (a == "--glossy-threshold")
            o.glossy_thresholds = parse_list<float>(v, parse_float);
        else if (a == "--reference")
            o.reference = v;
        else if (a == "--reference-passes")
            o.reference_passes = static_cast<int>(parse_count(v));
        else if (a == "--reference-photons")
            o.reference_photons = static_cast<std::uint32_t>(parse_count(v));
        else if (a == "--reference-radius-scale")
            o.reference_radius_scale = parse_float(v);
        else if (a == "--cross-check")
            o.cross_check = v;
        else if (a == "--device")
            o.device = static_cast<int>(parse_integer(a, v));
        else
            return false;
    }
    for (float s : o.radius_scales)
        if (!(s > 0.0f)) throw std::invalid_argument("--radius-scale: must be > 0");
    if (!(o.reference_radius_scale > 0.0f))
        throw std::invalid_argument("--reference-radius-scale: must be > 0");
    return o.passes >= 1 && o.reference_passes >= 1;
}

nlohmann::json error_json(const ImageError& e) {
    return {{"rmse", e.rmse}, {"rel_mse", e.rel_mse}, {"mean_bias", e.mean_bias}};
}

void print_json(const ConvergeOptions& o, const Reference& ref, const ImageError* cross,
                const std::vector<double>& cross_regions, double automatic_radius,
                const std::vector<Run>& runs, const std::string& renderer) {
    using nlohmann::json;
    json reference = {{"path", ref.path},
                      {"source", ref.source},
                      {"passes", ref.passes},
                      {"created", ref.created},
                      {"seconds", ref.seconds}};
    if (ref.source == "analytic") reference["value"] = ref.value;
    json out = {{"bench", "converge"},    {"scene", o.scene},
                {"width", o.width},       {"height", o.height},
                {"renderer", renderer},   {"automatic_radius", automatic_radius},
                {"fit_from", o.fit_from}, {"reference", reference}};
    if (cross) {
        out["cross_check"] = error_json(*cross);
        out["cross_check"]["path"] = o.cross_check;
        out["cross_check"]["region_grid"] = kRegionGrid;
        out["cross_check"]["region_bias"] = cross_regions;
    }
    json runs_json = json::array();
    for (const Run& run : runs) {
        const RenderSettings& s = run.settings;
        json points = json::array();
        for (const Point& pt : run.points) {
            json p = error_json(pt.error);
            p["passes"] = pt.passes;
            p["seconds"] = pt.seconds;
            points.push_back(p);
        }
        runs_json.push_back({{"alpha", s.alpha},
                             {"photons_per_pass", s.photons_per_pass},
                             {"radius_scale", run.radius_scale},
                             {"initial_radius", s.initial_radius},
                             {"hash", to_string(s.hash)},
                             {"rng", to_string(s.rng)},
                             {"direct_light", to_string(s.direct_light)},
                             {"estimator", to_string(s.estimator)},
                             {"glossy_threshold", s.glossy_threshold},
                             {"slope", run.slope},
                             {"theoretical_slope", theoretical_slope(s.alpha)},
                             {"points", points}});
    }
    out["runs"] = runs_json;
    std::printf("%s\n", out.dump(1).c_str());
}

void print_table(const ConvergeOptions& o, const Reference& ref, const ImageError* cross,
                 const std::vector<Run>& runs, const std::string& renderer) {
    if (ref.source == "analytic")
        std::printf("%s: %s %dx%d, reference: the exact radiance %.6g\n", renderer.c_str(),
                    o.scene.c_str(), o.width, o.height, ref.value);
    else
        std::printf("%s: %s %dx%d, reference %s (%s, %ld passes%s)\n", renderer.c_str(),
                    o.scene.c_str(), o.width, o.height, ref.path.c_str(), ref.source.c_str(),
                    ref.passes, ref.created ? ", rendered now" : "");
    if (cross)
        std::printf("reference against %s: RMSE %.5f, relative MSE %.5f, mean bias %+.5f\n",
                    o.cross_check.c_str(), cross->rmse, cross->rel_mse, cross->mean_bias);
    std::printf("%6s %9s %7s %10s %5s %8s %5s %6s %8s %8s %10s %10s %10s %10s\n", "alpha",
                "photons", "radius", "hash", "rng", "direct", "est", "glossy", "slope", "theory",
                "passes", "seconds", "RMSE", "mean bias");
    for (const Run& run : runs) {
        const Point& last = run.points.back();
        std::printf("%6.3f %9u %7.3g %10s %5s %8s %5s %6.3g %8.3f %8.3f %10d %10.3f %10.5f "
                    "%+10.5f\n",
                    run.settings.alpha, run.settings.photons_per_pass, run.radius_scale,
                    to_string(run.settings.hash).c_str(), to_string(run.settings.rng).c_str(),
                    to_string(run.settings.direct_light).c_str(),
                    to_string(run.settings.estimator).c_str(), run.settings.glossy_threshold,
                    run.slope,
                    theoretical_slope(run.settings.alpha), last.passes, last.seconds,
                    last.error.rmse, last.error.mean_bias);
    }
}

}  // namespace

int bench_converge(int argc, char** argv) {
    ConvergeOptions o;
    try {
        if (!parse(argc, argv, o)) return usage();
        // The furnace's reference is its exact radiance unless a file is named.
        if (o.reference.empty() && o.scene != "furnace") o.reference = default_reference_path(o);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "glslppm-bench converge: %s\n", e.what());
        return 2;
    }
    try {
        const Scene scene = make_bench_scene(o.scene, float(o.width) / float(o.height));
        // The automatic radius of this scene and size, which --radius-scale multiplies.
        RenderSettings probe;
        probe.width = o.width;
        probe.height = o.height;
        probe.photons_per_pass = 1024;
        probe.device = o.device;
        RenderStats probe_stats;
        {
            Renderer probe_renderer(scene, probe);
            probe_stats = probe_renderer.stats();
        }
        const double automatic = probe_stats.initial_radius;
        const Reference ref = load_or_make_reference(o, scene, automatic);
        ImageError cross_error;
        const ImageError* cross = nullptr;
        std::vector<double> cross_regions;
        if (!o.cross_check.empty()) {
            const FloatImage other = read_exr(o.cross_check);
            if (other.width != o.width || other.height != o.height)
                throw std::invalid_argument("--cross-check " + o.cross_check + " is not " +
                                            std::to_string(o.width) + "x" +
                                            std::to_string(o.height));
            cross_error = image_error(ref.image.rgba, other);
            cross_regions = region_bias(ref.image.rgba, other);
            cross = &cross_error;
        }

        std::vector<Run> runs;
        std::uint64_t seed = 1;
        for (float alpha : o.alphas)
            for (std::uint32_t photons : o.photons)
                for (float scale : o.radius_scales)
                    for (HashMode hash : o.hashes)
                        for (RngKind rng : o.rngs)
                            for (DirectLight direct : o.directs)
                                for (Estimator estimator : o.estimators)
                                    for (float glossy : o.glossy_thresholds) {
                                        RenderSettings s = probe;
                                        s.glossy_threshold = glossy;
                                        s.photons_per_pass = photons;
                                        s.alpha = alpha;
                                        s.initial_radius = static_cast<float>(scale * automatic);
                                        s.hash = hash;
                                        s.rng = rng;
                                        s.direct_light = direct;
                                        s.estimator = estimator;
                                        s.seed = seed++;
                                        validate(s);  // pppm with the paper's generator: an error
                                        runs.push_back(converge_run(scene, s, scale, o, ref.image));
                                        if (!o.json)
                                            std::fprintf(stderr, "  run %zu done\n", runs.size());
                                    }
        if (o.json)
            print_json(o, ref, cross, cross_regions, automatic, runs, probe_stats.renderer);
        else
            print_table(o, ref, cross, runs, probe_stats.renderer);
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "glslppm-bench converge: %s\n", e.what());
        return 1;
    }
}
