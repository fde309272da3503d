// The features step of prepare_scene: the programs' #defines, chosen from what the prepared
// scene uses (the rows of render/specializations.h) and from the settings' methods and
// outputs, and the variant's name (render/scene_preparation.h). The defines keep one order
// (the program cache's key): geometry, lights and materials, outputs, direct light, methods
// and sizes, light tracing.
#include <algorithm>
#include <stdexcept>

#include "render/density_estimator.h"
#include "render/specializations.h"

namespace glslppm {
namespace {

// The defines and the variant's feature names as they are chosen.
struct Features {
    const FeatureInputs& in;
    PreparedScene& p;
    std::vector<std::string> names;

    void add(const std::string& define, const std::string& name, const std::string& value = "1") {
        p.defines.push_back({define, value});
        if (!name.empty()) names.push_back(name);
    }

    // The table's rows of one group: compiled where the scene needs them, where the full
    // variant takes them, or where a benchmark forces them (RenderSettings::forced_features).
    void rows(SpecializationGroup group) {
        const RenderSettings& s = in.settings;
        for (const Specialization& row : specializations()) {
            if (row.group != group) continue;
            const bool forced = std::find(s.forced_features.begin(), s.forced_features.end(),
                                          row.name) != s.forced_features.end();
            const bool applies = row.applies == nullptr || row.applies(in);
            if (!row.needed(in) &&
                !(applies && (forced || (s.full_variant && row.in_full_variant))))
                continue;
            if (row.defines == nullptr) {
                add(row.define, row.name);
                continue;
            }
            for (const auto& [define, value] : row.defines(in))
                p.defines.push_back({define, value});
            names.push_back(row.name);
        }
    }
};

// Methods and outputs, not scene features: the full variant leaves them as the settings say.
void output_and_method_defines(unsigned local_size, Features& f) {
    PreparedScene& p = f.p;
    const RenderSettings& settings = f.in.settings;
    f.add(settings.rng == RngKind::Pcg ? "RNG_PCG" : "RNG_PAPER", "");
    f.add(settings.hash == HashMode::Exact ? "HASH_EXACT" : "HASH_STOCHASTIC", "");
    f.add("LOCAL_SIZE", "", std::to_string(local_size) + "u");
    f.add("RADIUS_STATS_THREADS", "", std::to_string(kRadiusStatsThreads) + "u");
    f.names.push_back("rng=" + to_string(settings.rng));
    f.names.push_back("hash=" + to_string(settings.hash));
    f.names.push_back("direct=" + to_string(settings.direct_light));
    const DensityEstimator& estimator = density_estimator(settings.estimator);
    if (estimator.define) f.add(estimator.define, "estimator=" + std::string(estimator.name));
    const PassLayout passes =
        pass_layout(settings.passes, settings.direct_light == DirectLight::Photons,
                    static_cast<int>(f.in.scene.light_groups.size()));
    for (const auto& d : pass_defines(passes)) p.defines.push_back(d);
    if (!passes.passes.empty()) {
        std::string names;
        for (RenderPass pass : passes.passes)
            names += (names.empty() ? "" : "+") + std::string(render_pass_info(pass).name);
        f.names.push_back("passes=" + names);
    }
    p.pass_layout = passes;
}

// What VCM's eye paths do not model yet (docs/vcm.md): an error naming it. Its light
// tracing is its own technique, not the photons' (light tracing is off under it).
void check_vcm_supports(const Scene& scene) {
    if (!scene.light_link_receives.empty())
        throw std::invalid_argument("estimator vcm: light linking is not supported yet");
}

}  // namespace

void choose_features(const Scene& scene, const RenderSettings& settings, unsigned local_size,
                     const PackedBvh& bvh, PreparedScene& p) {
    for (const std::string& name : settings.forced_features) {
        const auto rows = specializations();
        if (std::none_of(rows.begin(), rows.end(),
                         [&](const Specialization& row) { return name == row.name; }))
            throw std::invalid_argument("forced_features: no specialization is named '" + name +
                                        "'");
    }
    RenderSettings chosen = settings;
    if (settings.estimator == Estimator::Vcm) {
        check_vcm_supports(scene);
        chosen.light_tracing = false;
    }
    const FeatureInputs in{scene, chosen, bvh, p, traces_smooth_specular(scene, bvh, p)};
    Features f{in, p, {}};
    f.rows(SpecializationGroup::Scene);
    if (settings.transparent) {
        f.add("FILM_TRANSPARENT", "transparent");
        if (settings.transparent_glass) f.add("FILM_TRANSPARENT_GLASS", "transparent-glass");
    }
    // Light sampling at the visible points (shaders/common/light_sampling.glsl).
    if (settings.direct_light != DirectLight::Photons) f.add("DIRECT_LIGHT_SAMPLED", "");
    // VCM's light tracing technique (common/vcm_light_paths.glsl) splats as light tracing does.
    if (settings.vcm_techniques == VcmTechniques::LightTracing)
        f.add("VCM_LIGHT_TRACING", "vcm=lt");
    // Both, weighted against each other (common/vcm_mis.glsl).
    const VcmTechniques t = settings.vcm_techniques;
    if (t == VcmTechniques::PathAndLightTracing) f.add("VCM_MIS", "vcm=pt+lt");
    if (t == VcmTechniques::PathAndLightTracingEyePart) {
        f.add("VCM_MIS", "vcm=pt+lt:eye");
        f.add("VCM_MIS_EYE_PART", "");
    }
    if (t == VcmTechniques::PathAndLightTracingLightPart) {
        f.add("VCM_MIS", "vcm=pt+lt:light");
        f.add("VCM_MIS_LIGHT_PART", "");
    }
    // Vertex merging besides (common/vcm_merging.glsl).
    if (vcm_merges(t)) {
        const bool part = t == VcmTechniques::PathLightTracingAndMergingMergePart;
        f.add("VCM_MIS", part ? "vcm=pt+lt+vm:merge" : "vcm=pt+lt+vm");
        f.add("VCM_MERGING", "");
        if (part) f.add("VCM_MERGE_PART", "");
    }
    if (t != VcmTechniques::PathTracing && t != VcmTechniques::LightTracing)
        f.add("VCM_LIGHT_TRACING", "");
    f.rows(SpecializationGroup::DirectLight);
    // Emitter MIS finds a hit triangle's record through the triangles' map.
    const auto& d = p.defines;
    if (std::any_of(d.begin(), d.end(), [](const auto& x) { return x.first == "HAS_EMITTER_MIS"; }))
        append_triangle_map(p.emitters);
    output_and_method_defines(local_size, f);
    f.rows(SpecializationGroup::Last);
    p.light_tracing = std::any_of(d.begin(), d.end(),
                                  [](const auto& x) {
                                      return x.first == "HAS_LIGHT_TRACING" ||
                                             x.first == "VCM_LIGHT_TRACING";
                                  });
    for (const std::string& name : f.names) p.variant += (p.variant.empty() ? "" : ",") + name;
}

}  // namespace glslppm
