// What a user chooses for a render (the add-on's scene.glslppm, the CLI's options).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "render/render_passes.h"

namespace glslppm {

enum class HashMode { Stochastic, Exact };
enum class RngKind { Paper, Pcg };
// Where a visible point's direct light comes from: a light sample and a shadow ray each pass
// (photons then carry only light that has scattered at least once), or photons alone, as in
// Hachisuka 2015.
// Sampled: light samples, combined by MIS with a BSDF sample at glossy visible points and
// (in a fraction emitter_mis_fraction of passes) at Lambertian ones;
// SampledNoMis: light samples alone for every emitter but the world (MIS's baseline, as
// the renderer was before it: docs/direct_light.md); Photons: the photons alone.
enum class DirectLight { Sampled, Photons, SampledNoMis };
// How passes combine. SPPM (Hachisuka and Jensen 2009) shrinks each pixel's radius from its
// own photon count, so pass k+1 depends on pass k. PPPM (Knaus and Zwicker 2011) gives pass i
// the radius r_1 s(i) and its own estimate, seeded by (seed, i) alone: the image is the mean
// of the passes' estimates, so any set of pass indices can run on any device or machine and
// the means merge exactly (render/film_merge.h). What each one decides is its description
// in render/density_estimator.h. VCM (Georgiev et al. 2012; docs/vcm.md): passes as PPPM's,
// each an eye subpath per pixel; so far its path tracing technique alone.
enum class Estimator { Sppm, Pppm, Vcm };
// VCM's techniques for tests (docs/vcm.md): path tracing alone, or light tracing alone (the
// eye path keeps only the emission it meets before any rough scatter).
// pt: path tracing alone; lt: light tracing alone (unweighted); pt+lt: both, weighted by
// multiple importance sampling where both can sample a path (docs/vcm.md); pt+lt:eye and
// pt+lt:light: one side's weighted part of pt+lt alone, for the test that they add up.
enum class VcmTechniques {
    PathTracing,
    LightTracing,
    PathAndLightTracing,
    PathAndLightTracingEyePart,
    PathAndLightTracingLightPart,
    // Path tracing, light tracing and vertex merging ("pt+lt+vm", docs/vcm.md), and the
    // merges alone ("pt+lt+vm:merge", for the tests).
    PathLightTracingAndMerging,
    PathLightTracingAndMergingMergePart
};
// Whether VCM's vertex merging runs (its light paths store photons, its eye paths hold
// visible points that gather them).
bool vcm_merges(VcmTechniques techniques);
// How a scene's instances are traced: through a two-level MTBVH, flattened into world-space
// triangles, or chosen by the measured rule in render/instancing.h.
enum class Instancing { Auto, TwoLevel, Flattened };
// How a diffuse lobe under a bumped or normal-mapped normal fades towards the shadow
// terminator, as the Cycles of the user's Blender does: Chiang, Li and Burley 2019 ("Taming
// the Shadow Terminator"; Cycles up to 4.x) or Conty Estevez, Lecocq and Stein 2021 ("A
// Microfacet-Based Shadowing Function to Solve the Bump Terminator Problem"; Cycles 5.x).
enum class BumpShadowing { Chiang2019, Conty2021 };

struct RenderSettings {
    int width = 256;
    int height = 256;
    std::uint32_t photons_per_pass = 65536;
    float alpha = 0.7f;           // SPPM's fraction of new photons kept (Hachisuka 2009)
    float initial_radius = 0.0f;  // 0: automatic, from the scene size and the pixel footprint
    float radius_scale = 1.0f;    // multiplies the automatic initial radius
    // Cycles' Light Paths (docs/bounces.md): a full path (eye subpath, visible point, photon
    // subpath) keeps its light while the scatters before its last one number at most
    // max_bounces in all and at most each kind's limit in their kind, as Cycles' path_state_next
    // counts them; 0 keeps direct light only. The kinds' defaults here (1024) leave the total
    // alone in charge, so module and CLI renders keep their images; the add-on passes
    // Blender's Light Paths settings (Cycles' defaults: 12, 4, 4, 12).
    int max_bounces = 16;
    int max_diffuse_bounces = 1024;
    int max_glossy_bounces = 1024;
    int max_transmission_bounces = 1024;
    // Microfacet lobes below this roughness are followed by eye paths (sampled, as mirrors
    // and glass are); at and above it they hold the visible point that gathers photons.
    // 0.5: chosen when a visible point's direct light was a light sample alone, whose noise
    // on narrower lobes is large (a white conductor of roughness 0.3 under a uniform sky
    // read 0.95-1.08 after 64 passes where following the lobe reads 1.000). Light and BSDF
    // samples are now combined by MIS there (docs/direct_light.md), but the photons'
    // gather on a glossy lobe stays noisy: on the glossy Cornell box 0.5 still gives 0.0264
    // RMSE outside the light against 0.0433 at 0.2 (256 passes, scripts/emitter_mis_regions.py).
    float glossy_threshold = 0.5f;
    // Issue 30: the probability q with which a Lambertian visible point takes the BSDF sample
    // that looks for emissive triangles (and the world) beside its light sample, decided per
    // work group of 64 pixels and pass so that a GPU's warps skip the ray together. The two
    // samples are weighed by the balance heuristic with q BSDF samples, unbiased for any q in
    // (0, 1] (docs/direct_light.md); 1: every pass. Glossy points always take it.
    float emitter_mis_fraction = 0.25f;
    HashMode hash = HashMode::Stochastic;
    RngKind rng = RngKind::Pcg;   // docs/rng.md: better in dieharder and faster
    // docs/direct_light.md: less error at equal time.
    DirectLight direct_light = DirectLight::Sampled;
    int device = -1;              // EGL device index; -1: $GLSLPPM_DEVICE or the first GPU
    // Several EGL devices, one worker each (pppm only); empty: `device` alone.
    std::vector<int> devices;
    Estimator estimator = Estimator::Sppm;
    VcmTechniques vcm_techniques = VcmTechniques::PathTracing;  // estimator vcm only
    // Light tracing of caustics seen directly (L S+ D E paths: shaders/common/light_tracing.glsl,
    // docs/light_tracing.md): photons of pure mirror and glass chains are connected to the
    // camera instead of gathered there. Compiled only where the scene has smooth specular
    // surfaces and the closed material model, with a pinhole or orthographic camera and no
    // light-split passes (native/render/scene_features.cpp).
    bool light_tracing = true;
    // SPPM: before a film's first pass, photon steps that bring the paths carried across
    // passes near their stationary state (Renderer::Gpu::warm_up_photon_paths). Off for the
    // viewport, whose restarts on every camera move must stay quick.
    bool photon_warm_up = true;
    std::uint64_t first_pass = 0;  // pppm: run() continues from this pass index
    std::uint64_t seed = 0;
    int leaf_size = 4;            // BVH leaf size (triangles)
    bool profile = false;         // time each stage with GL timer queries (waits every pass)
    // Compile every feature whether the scene uses it or not (the specialization
    // benchmark's baseline); off, programs model only what the scene requires.
    bool full_variant = false;
    // Compile these rows of render/specializations.h (by name) as if the scene needed them:
    // how glslppm-bench specialize --each measures each row's gain.
    std::vector<std::string> forced_features;
    int max_texture_size = 0;     // 0: the GPU's GL_MAX_TEXTURE_SIZE; smaller tests downscaling
    // 0: the GPU's GL_MAX_SHADER_STORAGE_BLOCK_SIZE; smaller caps the per-pixel buffers
    // below it, so that tests tile small images (native/render/tiled_render.h).
    std::uint64_t max_block_bytes = 0;
    // Film alpha = coverage: camera rays that leave the scene are transparent and show no
    // world (Blender's Film > Transparent); with transparent_glass, so are those that leave
    // through smooth glass, in proportion to what the glass transmits.
    bool transparent = false;
    bool transparent_glass = false;
    Instancing instancing = Instancing::Auto;
    BumpShadowing bump_shadowing = BumpShadowing::Chiang2019;
    // Render passes beside Combined (render/render_passes.h); empty: Combined alone, and
    // programs without any pass code.
    std::vector<RenderPass> passes;
};

HashMode parse_hash_mode(const std::string& name);  // "stochastic" | "exact"
RngKind parse_rng_kind(const std::string& name);    // "paper" | "pcg"
DirectLight parse_direct_light(const std::string& name);  // "sampled" | "photons" | "sampled-no-mis"
Estimator parse_estimator(const std::string& name);       // "sppm" | "pppm" | "vcm"
// "pt" | "lt" | "pt+lt" | "pt+lt:eye" | "pt+lt:light" | "pt+lt+vm" | "pt+lt+vm:merge"
VcmTechniques parse_vcm_techniques(const std::string& name);
std::string to_string(VcmTechniques techniques);
Instancing parse_instancing(const std::string& name);  // "auto" | "two-level" | "flattened"
std::string to_string(HashMode mode);
std::string to_string(RngKind kind);
std::string to_string(DirectLight direct);
std::string to_string(Estimator estimator);
std::string to_string(Instancing instancing);
BumpShadowing parse_bump_shadowing(const std::string& name);  // "chiang2019" | "conty2021"
std::string to_string(BumpShadowing shadowing);

// Throws std::invalid_argument naming the setting when one is out of range.
void validate(const RenderSettings& settings);

}  // namespace glslppm
