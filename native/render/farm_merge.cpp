#include "render/farm_merge.h"

#include <algorithm>
#include <cstdio>
#include <set>
#include <sstream>

#include "render/density_estimator.h"
#include "render/film_merge.h"

namespace glslppm {

std::string format_pass_ranges(const PassRanges& ranges) {
    std::string text;
    for (const auto& [first, end] : ranges) {
        if (!text.empty()) text += ',';
        text += std::to_string(first);
        text += '-';
        text += std::to_string(end);
    }
    return text;
}

PassRanges parse_pass_ranges(const std::string& text) {
    PassRanges ranges;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        unsigned long long first = 0, end = 0;
        char tail = 0;
        if (std::sscanf(item.c_str(), "%llu-%llu%c", &first, &end, &tail) != 2 || first >= end ||
            (!ranges.empty() && first < ranges.back().second))
            throw std::invalid_argument("'" + text + "' is not sorted, disjoint ranges first-end");
        ranges.push_back({first, end});
    }
    return ranges;
}

// The settings that shape the image, as "name=value;..." for the EXR attribute farm merges
// compare. max_bounces is written under its earlier name max_depth: frames rendered before
// the rename must still merge with those rendered after. The per-kind limits come last, and
// only where one is set below the total's reach (a limit of max_bounces or more cuts
// nothing), so that frames of the settings before them keep the same string.
std::string image_settings(const RenderSettings& s) {
    char text[512];
    std::snprintf(text, sizeof text,
                  "width=%d;height=%d;photons_per_pass=%u;alpha=%.9g;initial_radius=%.9g;"
                  "radius_scale=%.9g;max_depth=%d;hash=%s;rng=%s;direct_light=%s;leaf_size=%d;"
                  "max_texture_size=%d;transparent=%d;transparent_glass=%d;glossy_threshold=%.9g",
                  s.width, s.height, s.photons_per_pass, s.alpha, s.initial_radius, s.radius_scale,
                  s.max_bounces, to_string(s.hash).c_str(), to_string(s.rng).c_str(),
                  to_string(s.direct_light).c_str(), s.leaf_size, s.max_texture_size,
                  s.transparent ? 1 : 0, s.transparent_glass ? 1 : 0, s.glossy_threshold);
    std::string settings = text;
    for (const auto& [name, value] :
         {std::pair<const char*, int>{"max_diffuse_bounces", s.max_diffuse_bounces},
          {"max_glossy_bounces", s.max_glossy_bounces},
          {"max_transmission_bounces", s.max_transmission_bounces}})
        if (value < s.max_bounces) settings += ";" + std::string(name) + "=" + std::to_string(value);
    return settings;
}

std::map<std::string, std::string> farm_attributes(const RenderSettings& settings,
                                                   const RenderStats& stats) {
    return {{"glslppm.estimator", to_string(settings.estimator)},
            {"glslppm.seed", std::to_string(settings.seed)},
            {"glslppm.settings", image_settings(settings)},
            {"glslppm.scene_hash", stats.scene_hash},
            {"glslppm.pass_ranges", format_pass_ranges(stats.pass_ranges)},
            {"glslppm.passes", std::to_string(stats.passes)}};
}

namespace {

const std::string& field(const FarmInput& in, const std::string& name) {
    const auto it = in.exr.attributes.find(name);
    if (it == in.exr.attributes.end())
        throw FarmMergeError(in.path + ": " + name +
                             " is missing (not a glslppm render, or one "
                             "written before farm merging)");
    return it->second;
}

// The first "name=value" of two settings strings that differ.
std::string first_difference(const std::string& a, const std::string& b) {
    std::stringstream sa(a), sb(b);
    std::string ia, ib;
    while (true) {
        const bool ha = static_cast<bool>(std::getline(sa, ia, ';'));
        const bool hb = static_cast<bool>(std::getline(sb, ib, ';'));
        if (!ha && !hb) return "";
        if (ia != ib || ha != hb) {
            std::string out = hb ? ib : std::string("(none)");
            out += " where it has ";
            out += ha ? ia : std::string("(none)");
            return out;
        }
    }
}

// The render passes a file carries: its channels' names without the channel letter
// ("ViewLayer.Depth" for "ViewLayer.Depth.Z"; a single-layer file's R, G, B, A are "Combined").
std::set<std::string> render_pass_names(const ExrChannels& exr) {
    std::set<std::string> names;
    for (const auto& [channel, plane] : exr.channels) {
        const std::size_t dot = channel.rfind('.');
        names.insert(dot == std::string::npos ? std::string("Combined") : channel.substr(0, dot));
    }
    return names;
}

std::set<std::string> channel_names(const ExrChannels& exr) {
    std::set<std::string> names;
    for (const auto& [channel, plane] : exr.channels) names.insert(channel);
    return names;
}

// "A, B only in a.exr; C only in b.exr" for two sets that differ.
std::string describe_difference(const std::set<std::string>& a, const std::string& a_path,
                                const std::set<std::string>& b, const std::string& b_path) {
    auto only = [](const std::set<std::string>& x, const std::set<std::string>& y,
                   const std::string& path) {
        std::string list;
        for (const std::string& name : x) {
            if (y.count(name)) continue;
            if (!list.empty()) list += ", ";
            list += name;
        }
        return list.empty() ? list : list + " only in " + path;
    };
    const std::string in_a = only(a, b, a_path), in_b = only(b, a, b_path);
    return in_a + (!in_a.empty() && !in_b.empty() ? "; " : "") + in_b;
}

// Throws unless `in` renders the same frame as `first`: an estimator of independent passes
// (render/density_estimator.h), the same scene, seed, settings, size and render passes.
void check_same_frame(const FarmInput& first, const FarmInput& in) {
    const std::string& name = field(in, "glslppm.estimator");
    const DensityEstimator* estimator = find_density_estimator(name);
    if (!estimator || !estimator->independent_passes)
        throw FarmMergeError(in.path + ": glslppm.estimator is " + name + ": only " +
                             independent_estimator_names() + " renders merge (" +
                             (estimator
                                  ? std::string(estimator->title) + "'s passes depend on each other"
                                  : "not an estimator") +
                             ")");
    for (const char* name : {"glslppm.scene_hash", "glslppm.seed"}) {
        if (field(in, name) != field(first, name))
            throw FarmMergeError(in.path + ": " + name + " " + field(in, name) + " differs from " +
                                 first.path + "'s " + field(first, name));
    }
    if (field(in, "glslppm.settings") != field(first, "glslppm.settings"))
        throw FarmMergeError(
            in.path + ": glslppm.settings has " +
            first_difference(field(first, "glslppm.settings"), field(in, "glslppm.settings")) +
            " in " + first.path);
    if (in.exr.width != first.exr.width || in.exr.height != first.exr.height)
        throw FarmMergeError(in.path + ": size " + std::to_string(in.exr.width) + "x" +
                             std::to_string(in.exr.height) + " differs from " + first.path + "'s " +
                             std::to_string(first.exr.width) + "x" +
                             std::to_string(first.exr.height));
    // Every layer merges with its own kind only: a pass that one file lacks cannot be
    // averaged over the passes of all.
    const auto layers = render_pass_names(in.exr), first_layers = render_pass_names(first.exr);
    const auto channels = channel_names(in.exr), first_channels = channel_names(first.exr);
    if (layers != first_layers || channels != first_channels) {
        const bool by_layer = layers != first_layers;
        throw FarmMergeError(
            in.path + ": render passes differ from " + first.path + "'s: " +
            (by_layer ? describe_difference(first_layers, first.path, layers, in.path)
                      : describe_difference(first_channels, first.path, channels, in.path)));
    }
}

std::uint64_t pass_count(const PassRanges& ranges) {
    std::uint64_t count = 0;
    for (const auto& r : ranges) count += r.second - r.first;
    return count;
}

// The file's pass ranges, checked against its pass count.
PassRanges checked_pass_ranges(const FarmInput& in) {
    PassRanges ranges;
    try {
        ranges = parse_pass_ranges(field(in, "glslppm.pass_ranges"));
    } catch (const std::invalid_argument& e) {
        throw FarmMergeError(in.path + ": glslppm.pass_ranges " + e.what());
    }
    const std::uint64_t count = pass_count(ranges);
    if (std::to_string(count) != field(in, "glslppm.passes"))
        throw FarmMergeError(in.path + ": glslppm.passes " + field(in, "glslppm.passes") +
                             " is not the " + std::to_string(count) + " of its pass ranges");
    return ranges;
}

}  // namespace

ExrChannels merge_farm_renders(const std::vector<FarmInput>& inputs) {
    if (inputs.empty()) throw FarmMergeError("no files to merge");
    const FarmInput& first = inputs[0];
    std::vector<std::pair<std::pair<std::uint64_t, std::uint64_t>, std::size_t>> all;
    std::vector<std::uint64_t> passes;
    for (std::size_t k = 0; k < inputs.size(); ++k) {
        check_same_frame(first, inputs[k]);
        const PassRanges ranges = checked_pass_ranges(inputs[k]);
        for (const auto& r : ranges) all.push_back({r, k});
        passes.push_back(pass_count(ranges));
    }
    std::sort(all.begin(), all.end());
    for (std::size_t k = 1; k < all.size(); ++k) {
        const auto& [a, ia] = all[k - 1];
        const auto& [b, ib] = all[k];
        if (b.first < a.second)
            throw FarmMergeError(inputs[ib].path + ": glslppm.pass_ranges overlaps " +
                                 inputs[ia].path + "'s at pass " + std::to_string(b.first));
    }
    ExrChannels out{
        first.exr.width, first.exr.height, {}, first.exr.attributes, first.exr.multilayer};
    for (const auto& [name, plane] : first.exr.channels) {
        std::vector<const std::vector<float>*> planes;
        for (const FarmInput& in : inputs) planes.push_back(&in.exr.channels.at(name));
        out.channels[name] = merge_films(planes, passes);
    }
    PassRanges merged;
    for (const auto& [r, k] : all) {
        if (!merged.empty() && merged.back().second == r.first)
            merged.back().second = r.second;
        else
            merged.push_back(r);
    }
    const std::string total = std::to_string(pass_count(merged));
    out.attributes["glslppm.pass_ranges"] = format_pass_ranges(merged);
    out.attributes["glslppm.passes"] = total;
    out.attributes["passes"] = total;
    return out;
}

std::map<std::string, std::string> merge_farm_files(const std::vector<std::string>& paths,
                                                    const std::string& out) {
    std::vector<FarmInput> inputs;
    for (const std::string& path : paths) inputs.push_back({path, read_exr_file(path)});
    const ExrChannels merged = merge_farm_renders(inputs);
    write_exr_file(out, merged);
    return merged.attributes;
}

}  // namespace glslppm
