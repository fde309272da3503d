// Render passes beside Combined, for Blender's compositor (docs/passes.md): data of the
// surfaces the eye stage finds (Depth, Normal, the Denoising Normal and Albedo of the first
// diffuse-like surface, as Cycles writes them) and Combined's light split by path (Emission, Environment, Direct,
// Indirect, Caustics), which sums to Combined. Each enabled pass is one compensated sum per
// pixel in the pass films buffer (shaders/common/pass_films.glsl), at the slot its #define
// names; a pass that is not enabled is not compiled.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <string>
#include <utility>
#include <vector>

#include "image/exr.h"

namespace glslppm {

enum class RenderPass {
    Depth,            // camera z-depth of the first surface seen; 1e10 where none (Cycles)
    Normal,           // world normal of the first surface seen, facing the camera
    DenoisingNormal,  // Cycles' denoising normal (camera space; denoising_features.glsl)
    DenoisingAlbedo,  // Cycles' denoising albedo: the mean albedo of the diffuse-like lobes
    Emission,         // emission of surfaces seen directly or through specular chains
    Environment,      // the world seen directly or through specular chains
    Direct,           // light from a light, scattered once (sampled, or first-hit photons)
    Indirect,         // photons that scattered at least once, diffusely only
    Caustics,         // photons whose path had a specular or glossy (followed) bounce
};

struct RenderPassInfo {
    RenderPass pass;
    const char* name;           // the module's and CLI's name: "depth", "denoising_albedo", ...
    const char* blender;        // Blender 4.x's pass name (3.x: render_pass_blender_3x)
    const char* define;         // the shaders' slot define
    int channels;               // 1 (Depth) or 3
    const char* channel_names;  // Blender's channel letters: "Z", "XYZ" or "RGB"
    bool light;                 // part of Combined's split
};

// Every pass, in slot order.
const std::vector<RenderPassInfo>& render_pass_catalog();
const RenderPassInfo& render_pass_info(RenderPass pass);
// "depth", ...; "all" is not a pass (parse_render_pass_list). std::invalid_argument names
// the unknown name and lists the known ones.
RenderPass parse_render_pass(const std::string& name);
// A comma-separated list, "all" or "combined" (Combined alone: no extra pass).
std::vector<RenderPass> parse_render_pass_list(const std::string& list);
// Blender 3.x named some passes shorter: "Z" channel of "Depth" stays, "Emit", "Env".
std::string render_pass_blender_3x(RenderPass pass);

// Where each enabled pass lives in a pixel's record of the pass films: a (sum,
// compensation) pair of vec4 per pass, and Direct with photons a second pair for the
// photons that come straight from a light (their sum is scaled by SPPM's radius updates,
// so it cannot share the eye stage's).
struct PassLayout {
    std::vector<RenderPass> passes;     // enabled, catalog order, each once
    int offset(RenderPass pass) const;  // in vec4 from the pixel's first; -1: not enabled
    int stride = 0;                     // vec4 per pixel
    bool photon_split = false;          // photons carry their path's class (PASS_PHOTON_SPLIT)
    bool direct_photons = false;        // Direct has a photon pair (direct light = photons)
    // Light groups (docs/light_groups.md), after the passes: per group an eye pair (emission,
    // the world and light samples of the group's emitters) and a photon pair (its photons'
    // tau, scaled by the radius updates as Combined's is).
    int light_groups = 0;
    int light_group_offset(int group) const { return light_group_first + 4 * group; }
    int light_group_first = 0;  // vec4 from the pixel's first
};

// `direct_photons`: the render's direct light comes from photons (DirectLight::Photons);
// `light_groups`: the scene's (Scene::light_groups).
PassLayout pass_layout(const std::vector<RenderPass>& enabled, bool direct_photons,
                       int light_groups = 0);

// The programs' #defines: PASS_STRIDE, PASS_<NAME> = offset for each enabled pass, and
// PASS_PHOTON_SPLIT where photons must carry their class. None when no pass
// is enabled: the programs are those of a render without passes.
std::vector<std::pair<std::string, std::string>> pass_defines(const PassLayout& layout);

// What resolves a pass from its sums (as resolve_film.comp resolves Combined).
struct PassResolve {
    float inv_passes = 0.0f;           // 1 / passes
    float inv_photons_emitted = 0.0f;  // 1 / photon paths started (SPPM)
    // The photon passes are the mean of the passes' own estimates (FilmResolve::MeanOfPasses,
    // render/density_estimator.h: PPPM), else tau / (pi R^2 N_emitted).
    bool mean_of_passes = false;
};

// One pass's image, height x width x 4 (channels beyond the pass's are 0, alpha 1), from the
// pass films (pixels x layout.stride vec4) and, for SPPM's photon passes, the pixel
// statistics (pixels x (tau, N), (R, ...)). The photon passes are tau_c / (pi R^2 N_emitted)
// with the radius Combined uses, or PPPM's mean of pass estimates.
std::vector<float> resolve_render_pass(const PassLayout& layout, RenderPass pass,
                                       const std::vector<glm::vec4>& pass_films,
                                       const std::vector<glm::vec4>& pixel_stats,
                                       std::size_t pixels, const PassResolve& resolve);

// Light group `group`'s image, height x width x 4 (alpha 1), resolved as Direct with photons:
// its eye pair's mean plus its photons' tau / (pi R^2 N_emitted), or PPPM's mean.
std::vector<float> resolve_light_group(const PassLayout& layout, int group,
                                       const std::vector<glm::vec4>& pass_films,
                                       const std::vector<glm::vec4>& pixel_stats,
                                       std::size_t pixels, const PassResolve& resolve);

// Light tracing's splats of one light group (its block of the splat buffer, pixels x
// kLightSplatBytes / 4 words: common/light_splats.glsl) added to the group's image, as
// resolve_film.comp adds Combined's: the float sum times `scale` (1 / N_emitted, or PPPM's
// 1 / passes) over the film's pixel area `pixel_area`.
void add_light_group_splats(std::vector<float>& image, const std::vector<std::uint32_t>& words,
                            float scale, float pixel_area);

// Cycles' name of a light group's pass: "Combined_<group>".
std::string light_group_pass_name(const std::string& group);

// A render as the layers of a multi-layer EXR (glslppm-render --passes-out, the module's
// Renderer.write_passes_exr): Combined (RGBA), then each pass under Blender's pass and channel
// names; `images` are the passes' images in the order of `passes`.
// Then each light group's as "Combined_<name>" (RGB), where given.
std::vector<ExrPass> render_pass_layers(const std::vector<float>& film,
                                        const std::vector<RenderPass>& passes,
                                        const std::vector<std::vector<float>>& images,
                                        const std::vector<std::string>& light_groups = {},
                                        const std::vector<std::vector<float>>& group_images = {});

}  // namespace glslppm
