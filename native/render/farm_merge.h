// Farm renders of one frame: each PPPM render writes into its EXR the pass indices it ran,
// the seed, the estimator, the settings that shape the image and a hash of the scene
// (farm_attributes); merge_farm_renders checks that the files belong together and that their
// pass sets are disjoint, then weights each film and render pass by its passes
// (render/film_merge.h).
#pragma once

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "image/exr.h"
#include "render/renderer.h"
#include "render/settings.h"

namespace glslppm {

// A file that cannot be merged: the message names the file and the field.
class FarmMergeError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

using PassRanges = std::vector<std::pair<std::uint64_t, std::uint64_t>>;

// "0-8,10-12": half-open ranges [0, 8) and [10, 12).
std::string format_pass_ranges(const PassRanges& ranges);
// Throws std::invalid_argument on anything else than sorted, disjoint "first-end" ranges.
PassRanges parse_pass_ranges(const std::string& text);

// The settings that shape the image, as "name=value" joined by ';', in a fixed order (the
// device, the first pass and profiling are left out: they do not change a pass).
std::string image_settings(const RenderSettings& settings);

// The EXR header attributes of a render: glslppm.estimator, .seed, .settings, .scene_hash,
// .pass_ranges and .passes.
std::map<std::string, std::string> farm_attributes(const RenderSettings& settings,
                                                   const RenderStats& stats);

struct FarmInput {
    std::string path;  // for messages
    ExrChannels exr;   // every layer the render wrote (Combined alone, or with its passes)
};

// The exact merge, with the attributes of the whole (the union of the pass ranges): every
// channel of every layer weighted by the files' pass counts, as Renderer::film and
// render_passes merge their workers' (each pass is a mean over the passes run, Depth and
// the Normals too). Throws FarmMergeError naming the file and field: a missing attribute, an
// estimator whose passes depend on each other (render/density_estimator.h: all but pppm), a
// different scene hash, seed, setting, size or set of render passes, pass sets that overlap.
ExrChannels merge_farm_renders(const std::vector<FarmInput>& inputs);

// glslppm-merge: reads the files, merges them and writes `out` with the whole's attributes,
// which it returns.
std::map<std::string, std::string> merge_farm_files(const std::vector<std::string>& paths,
                                                    const std::string& out);

}  // namespace glslppm
