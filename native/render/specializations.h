// The compile-time specializations of the GPU programs: one row per feature that a scene may
// need or not, with its #define, its name in the variant, what a scene needs for it and the
// measured gain of leaving it out where it is not needed. Scene preparation
// (scene_features.cpp) compiles a row's define where its `needed` holds; the full variant
// (RenderSettings::full_variant) compiles every row whose `in_full_variant` is set; the
// variant's name lists the rows' names; glslppm-bench specialize --each measures a row's gain
// by forcing it into programs of a scene that does not need it (forced_features); and the
// tests read the table through the module (`specializations()`).
//
// Settings that choose a method or an output (the estimator, the hash, the generator, direct
// light by sampling, render passes, a transparent film) also compile as #defines; they are
// the settings' own and not rows here (scene_features.cpp).
#pragma once

#include <span>
#include <string>
#include <utility>
#include <vector>

#include "bvh/packed_bvh.h"
#include "render/scene_preparation.h"

namespace glslppm {

// What a row decides from: the scene, the settings and what preparation made of them.
struct FeatureInputs {
    const Scene& scene;
    const RenderSettings& settings;
    const PackedBvh& bvh;
    const PreparedScene& p;
    bool smooth_specular = false;  // a conductor or dielectric is traced (rough ones too)
};

// Where in the programs' define list a row goes (the list keeps one order, the program
// cache's key): the scene's rows, those of direct light (after DIRECT_LIGHT_SAMPLED), and
// light tracing (after the methods and the passes it depends on).
enum class SpecializationGroup { Scene, DirectLight, Last };

struct Specialization {
    const char* name;    // in the variant's name; what forced_features names
    const char* define;  // what the shaders test
    const char* needs;   // what a scene needs for it, in words
    const char* gain;    // measured: what leaving it out saves where a scene does not need it
    SpecializationGroup group;
    // Compiled by the full variant; where not, `gain` says why.
    bool in_full_variant;
    bool (*needed)(const FeatureInputs&);
    // Whether the row can be compiled at all for this scene and these settings (the full
    // variant and forced_features compile it only then); null: always. A row that stands
    // for the scene's data rather than code beside it (an environment map, two levels)
    // applies only where it is needed.
    bool (*applies)(const FeatureInputs&) = nullptr;
    // The defines it adds, where not (define, "1").
    std::vector<std::pair<std::string, std::string>> (*defines)(const FeatureInputs&) = nullptr;
};

std::span<const Specialization> specializations();

// Whether a triangle of the scene, placed once or instanced, has a conductor or a
// dielectric (light tracing's precondition).
bool traces_smooth_specular(const Scene& scene, const PackedBvh& bvh, const PreparedScene& p);

}  // namespace glslppm
