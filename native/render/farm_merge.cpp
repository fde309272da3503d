#include "render/farm_merge.h"

#include <algorithm>
#include <cstdio>
#include <sstream>

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
// the rename must still merge with those rendered after.
std::string image_settings(const RenderSettings& s) {
    char text[512];
    std::snprintf(text, sizeof text,
                  "width=%d;height=%d;photons_per_pass=%u;alpha=%.9g;initial_radius=%.9g;"
                  "radius_scale=%.9g;max_depth=%d;hash=%s;rng=%s;direct_light=%s;leaf_size=%d;"
                  "max_texture_size=%d;transparent=%d;transparent_glass=%d;glossy_threshold=%.9g",
                  s.width, s.height, s.photons_per_pass, s.alpha, s.initial_radius,
                  s.radius_scale, s.max_bounces, to_string(s.hash).c_str(),
                  to_string(s.rng).c_str(), to_string(s.direct_light).c_str(), s.leaf_size,
                  s.max_texture_size, s.transparent ? 1 : 0, s.transparent_glass ? 1 : 0,
                  s.glossy_threshold);
    return text;
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
    const auto it = in.attributes.find(name);
    if (it == in.attributes.end())
        throw FarmMergeError(in.path + ": " + name + " is missing (not a glslppm render, or one "
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

}  // namespace

FloatImage merge_farm_renders(const std::vector<FarmInput>& inputs,
                              std::map<std::string, std::string>* attributes) {
    if (inputs.empty()) throw FarmMergeError("no files to merge");
    const FarmInput& first = inputs[0];
    std::vector<std::pair<std::pair<std::uint64_t, std::uint64_t>, std::size_t>> all;
    std::vector<std::uint64_t> passes;
    for (std::size_t k = 0; k < inputs.size(); ++k) {
        const FarmInput& in = inputs[k];
        const std::string& estimator = field(in, "glslppm.estimator");
        if (estimator != "pppm")
            throw FarmMergeError(in.path + ": glslppm.estimator is " + estimator +
                                 ": only pppm renders merge (SPPM's passes depend on each other)");
        for (const char* name : {"glslppm.scene_hash", "glslppm.seed"}) {
            if (field(in, name) != field(first, name))
                throw FarmMergeError(in.path + ": " + name + " " + field(in, name) + " differs from " +
                                     first.path + "'s " + field(first, name));
        }
        if (field(in, "glslppm.settings") != field(first, "glslppm.settings"))
            throw FarmMergeError(in.path + ": glslppm.settings has " +
                                 first_difference(field(first, "glslppm.settings"),
                                                  field(in, "glslppm.settings")) +
                                 " in " + first.path);
        if (in.image.width != first.image.width || in.image.height != first.image.height)
            throw FarmMergeError(in.path + ": size " + std::to_string(in.image.width) + "x" +
                                 std::to_string(in.image.height) + " differs from " + first.path +
                                 "'s " + std::to_string(first.image.width) + "x" +
                                 std::to_string(first.image.height));
        PassRanges ranges;
        try {
            ranges = parse_pass_ranges(field(in, "glslppm.pass_ranges"));
        } catch (const std::invalid_argument& e) {
            throw FarmMergeError(in.path + ": glslppm.pass_ranges " + e.what());
        }
        std::uint64_t count = 0;
        for (const auto& r : ranges) {
            count += r.second - r.first;
            all.push_back({r, k});
        }
        if (std::to_string(count) != field(in, "glslppm.passes"))
            throw FarmMergeError(in.path + ": glslppm.passes " + field(in, "glslppm.passes") +
                                 " is not the " + std::to_string(count) + " of its pass ranges");
        passes.push_back(count);
    }
    std::sort(all.begin(), all.end());
    for (std::size_t k = 1; k < all.size(); ++k) {
        const auto& [a, ia] = all[k - 1];
        const auto& [b, ib] = all[k];
        if (b.first < a.second)
            throw FarmMergeError(inputs[ib].path + ": glslppm.pass_ranges overlaps " +
                                 inputs[ia].path + "'s at pass " + std::to_string(b.first));
    }
    std::vector<const std::vector<float>*> films;
    for (const FarmInput& in : inputs) films.push_back(&in.image.rgba);
    FloatImage out{first.image.width, first.image.height, merge_films(films, passes)};
    if (attributes) {
        *attributes = first.attributes;
        PassRanges ranges;
        for (const auto& [r, k] : all) ranges.push_back(r);
        PassRanges merged;
        for (const auto& r : ranges) {
            if (!merged.empty() && merged.back().second == r.first) merged.back().second = r.second;
            else merged.push_back(r);
        }
        std::uint64_t total = 0;
        for (std::uint64_t n : passes) total += n;
        (*attributes)["glslppm.pass_ranges"] = format_pass_ranges(merged);
        (*attributes)["glslppm.passes"] = std::to_string(total);
        (*attributes)["passes"] = std::to_string(total);
    }
    return out;
}

std::map<std::string, std::string> merge_farm_files(const std::vector<std::string>& paths,
                                                    const std::string& out) {
    std::vector<FarmInput> inputs;
    for (const std::string& path : paths) {
        FarmInput in;
        in.path = path;
        in.image = read_exr(path, &in.attributes);
        inputs.push_back(std::move(in));
    }
    std::map<std::string, std::string> attributes;
    const FloatImage merged = merge_farm_renders(inputs, &attributes);
    write_exr(out, merged, attributes);
    return attributes;
}

}  // namespace glslppm
