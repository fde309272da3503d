#include "render/settings.h"

#include <cmath>
#include <stdexcept>

#include "render/density_estimator.h"
#include "render/render_passes.h"

namespace glslppm {

HashMode parse_hash_mode(const std::string& name) {
    if (name == "stochastic") return HashMode::Stochastic;
    if (name == "exact") return HashMode::Exact;
    throw std::invalid_argument("hash: '" + name + "' is not a hash mode (stochastic, exact)");
}

RngKind parse_rng_kind(const std::string& name) {
    if (name == "paper") return RngKind::Paper;
    if (name == "pcg") return RngKind::Pcg;
    throw std::invalid_argument("rng: '" + name + "' is not a generator (paper, pcg)");
}

DirectLight parse_direct_light(const std::string& name) {
    if (name == "sampled") return DirectLight::Sampled;
    if (name == "photons") return DirectLight::Photons;
    if (name == "sampled-no-mis") return DirectLight::SampledNoMis;
    throw std::invalid_argument("direct_light: '" + name +
                                "' is not a direct-light mode (sampled, photons, sampled-no-mis)");
}

Estimator parse_estimator(const std::string& name) {
    if (const DensityEstimator* e = find_density_estimator(name)) return e->id;
    std::string names;
    for (const DensityEstimator& e : density_estimators())
        names += (names.empty() ? "" : ", ") + std::string(e.name);
    throw std::invalid_argument("estimator: '" + name + "' is not an estimator (" + names + ")");
}

VcmTechniques parse_vcm_techniques(const std::string& name) {
    if (name == "pt") return VcmTechniques::PathTracing;
    if (name == "lt") return VcmTechniques::LightTracing;
    if (name == "pt+lt") return VcmTechniques::PathAndLightTracing;
    if (name == "pt+lt:eye") return VcmTechniques::PathAndLightTracingEyePart;
    if (name == "pt+lt:light") return VcmTechniques::PathAndLightTracingLightPart;
    if (name == "pt+lt+vm") return VcmTechniques::PathLightTracingAndMerging;
    if (name == "pt+lt+vm:merge") return VcmTechniques::PathLightTracingAndMergingMergePart;
    throw std::invalid_argument(
        "vcm_techniques: '" + name +
        "' is not built (pt, lt, pt+lt, pt+lt:eye, pt+lt:light, pt+lt+vm, pt+lt+vm:merge)");
}

bool vcm_merges(VcmTechniques techniques) {
    return techniques == VcmTechniques::PathLightTracingAndMerging ||
           techniques == VcmTechniques::PathLightTracingAndMergingMergePart;
}

std::string to_string(VcmTechniques techniques) {
    switch (techniques) {
        case VcmTechniques::LightTracing: return "lt";
        case VcmTechniques::PathAndLightTracing: return "pt+lt";
        case VcmTechniques::PathAndLightTracingEyePart: return "pt+lt:eye";
        case VcmTechniques::PathAndLightTracingLightPart: return "pt+lt:light";
        case VcmTechniques::PathLightTracingAndMerging: return "pt+lt+vm";
        case VcmTechniques::PathLightTracingAndMergingMergePart: return "pt+lt+vm:merge";
        default: return "pt";
    }
}

Instancing parse_instancing(const std::string& name) {
    if (name == "auto") return Instancing::Auto;
    if (name == "two-level") return Instancing::TwoLevel;
    if (name == "flattened") return Instancing::Flattened;
    throw std::invalid_argument("instancing: '" + name +
                                "' is not an instancing mode (auto, two-level, flattened)");
}

BumpShadowing parse_bump_shadowing(const std::string& name) {
    if (name == "chiang2019") return BumpShadowing::Chiang2019;
    if (name == "conty2021") return BumpShadowing::Conty2021;
    throw std::invalid_argument("bump_shadowing: '" + name +
                                "' is not a bump shadowing term (chiang2019, conty2021)");
}

std::string to_string(BumpShadowing shadowing) {
    return shadowing == BumpShadowing::Conty2021 ? "conty2021" : "chiang2019";
}

std::string to_string(Instancing instancing) {
    return instancing == Instancing::Auto       ? "auto"
           : instancing == Instancing::TwoLevel ? "two-level"
                                                : "flattened";
}

std::string to_string(HashMode mode) { return mode == HashMode::Exact ? "exact" : "stochastic"; }
std::string to_string(RngKind kind) { return kind == RngKind::Pcg ? "pcg" : "paper"; }
std::string to_string(DirectLight direct) {
    return direct == DirectLight::Sampled        ? "sampled"
           : direct == DirectLight::SampledNoMis ? "sampled-no-mis"
                                                 : "photons";
}
std::string to_string(Estimator estimator) { return density_estimator(estimator).name; }

void validate(const RenderSettings& s) {
    auto fail = [](const std::string& what) { throw std::invalid_argument(what); };
    if (s.width < 1 || s.height < 1 || s.width > 16384 || s.height > 16384)
        fail("width/height: " + std::to_string(s.width) + "x" + std::to_string(s.height) +
             " is outside 1..16384");
    if (s.photons_per_pass < 1 || s.photons_per_pass > (1u << 26))
        fail("photons_per_pass: " + std::to_string(s.photons_per_pass) +
             " is outside 1..67108864");
    if (!(s.alpha > 0.0f && s.alpha <= 1.0f))
        fail("alpha: " + std::to_string(s.alpha) + " is outside (0, 1]");
    if (!(s.initial_radius >= 0.0f) || !std::isfinite(s.initial_radius))
        fail("initial_radius: must be 0 (automatic) or a positive distance");
    if (!(s.glossy_threshold >= 0.0f && s.glossy_threshold <= 1.0f))
        fail("glossy_threshold: must be a roughness in [0, 1]");
    if (!(s.emitter_mis_fraction > 0.0f && s.emitter_mis_fraction <= 1.0f))
        fail("emitter_mis_fraction: " + std::to_string(s.emitter_mis_fraction) +
             " is outside (0, 1] (the probability of a Lambertian point's BSDF sample)");
    if (!(s.radius_scale > 0.0f) || !std::isfinite(s.radius_scale))
        fail("radius_scale: must be a positive number");
    for (const auto& [name, value] :
         {std::pair<const char*, int>{"max_bounces", s.max_bounces},
          {"max_diffuse_bounces", s.max_diffuse_bounces},
          {"max_glossy_bounces", s.max_glossy_bounces},
          {"max_transmission_bounces", s.max_transmission_bounces}})
        if (value < 0 || value > 1024)
            fail(std::string(name) + ": " + std::to_string(value) + " is outside 0..1024");
    if (s.leaf_size < 1 || s.leaf_size > 64)
        fail("leaf_size: " + std::to_string(s.leaf_size) + " is outside 1..64");
    // What an estimator's passes allow (render/density_estimator.h).
    const DensityEstimator& estimator = density_estimator(s.estimator);
    if (estimator.independent_passes && s.rng == RngKind::Paper)
        fail("estimator: " + std::string(estimator.name) +
             " needs rng pcg (the paper's generator carries its state from one pass to the "
             "next, so a pass could not be run on its own)");
    if (!estimator.independent_passes && s.devices.size() > 1)
        fail("devices: several devices need estimator " + independent_estimator_names() + " (" +
             estimator.title + "'s passes depend on each other and cannot be split)");
    if (!estimator.independent_passes && s.first_pass != 0)
        fail("first_pass: only estimator " + independent_estimator_names() +
             " can start at a pass other than 0");
    if (s.estimator == Estimator::Vcm) {
        // What VCM does not model yet (docs/vcm.md): an error, never a wrong image.
        // Its data passes, Emission and Environment are written (docs/vcm.md); the light
        // split's Direct, Indirect and Caustics, whose parts its techniques do not keep apart
        // yet, are not.
        for (RenderPass pass : s.passes) {
            if (pass == RenderPass::Direct || pass == RenderPass::Indirect ||
                pass == RenderPass::Caustics)
                fail(std::string("estimator vcm: render pass '") + render_pass_info(pass).name +
                     "' (the light split: direct, indirect, caustics) is not supported yet");
        }
        if (s.direct_light != DirectLight::Sampled)
            fail("estimator vcm: direct_light must be 'sampled' (its path tracing technique)");
        if (s.profile) fail("estimator vcm: profile is not supported yet");
    } else if (s.vcm_techniques != VcmTechniques::PathTracing) {
        fail("vcm_techniques: needs estimator vcm");
    }
    if (s.first_pass > (std::uint64_t(1) << 52))
        fail("first_pass: " + std::to_string(s.first_pass) + " is above 2^52");
    for (std::size_t k = 0; k < s.devices.size(); ++k) {
        if (s.devices[k] < 0)
            fail("devices[" + std::to_string(k) + "]: " + std::to_string(s.devices[k]) +
                 " is not a device index");
    }
}

}  // namespace glslppm
