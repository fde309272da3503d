// SPPM stage 2, one thread per photon path, with path regeneration (Hachisuka 2015,
// section 3.3): each pass traces ONE bounce and stores at most one photon. A path killed
// by Russian roulette, by Cycles' Light Paths limits (common/bounces.glsl) or by leaving
// the scene starts anew from a light in the next pass, so every thread stays busy whatever
// the path lengths. Photons are
// stored on non-specular surfaces only, each with an independent random key for the
// stochastic hash; with light sampling (DIRECT_LIGHT_SAMPLED) not on a path's first hit.
layout(local_size_x = LOCAL_SIZE) in;

#define USES_PHOTON_PATHS
#define USES_PHOTONS
#define USES_EMITTERS
#include "common/frame.glsl"
#include "common/sppm_buffers.glsl"
#include "common/sampling.glsl"
#include "common/surface.glsl"
#include "common/bsdf.glsl"
#include "common/lobes.glsl"
#include "common/emitters.glsl"
#include "common/pass_films.glsl"
#include "common/bounces.glsl"
#ifdef HAS_ABSORPTION
#include "common/absorption.glsl"
#endif
#if defined(HAS_LIGHT_TRACING) || defined(VCM_LIGHT_TRACING)
#include "common/light_tracing.glsl"
#endif
#ifdef VCM_MIS
#include "common/vcm_mis.glsl"
#include "common/vcm_merging.glsl"
#endif
#include "common/light_linking.glsl"

// Light linking (common/light_linking.glsl): a photon that still carries its emitter's link
// set passes the surfaces that do not shadow that emitter, and is absorbed where it lands on
// a surface its light does not reach.
#ifdef LIGHT_LINKING
bool photon_link_absorbed = false;  // set by stores_photon
#define PHOTON_LINK_PASSES(m) photon_link_passes(m)
#else
const bool photon_link_absorbed = false;
#define PHOTON_LINK_PASSES(m) false
#endif

// The path's class rides in its flux.w for the light split's passes or for light tracing
// (the two are never on together: scene_features.cpp).
#if defined(PASS_PHOTON_SPLIT) || defined(HAS_LIGHT_TRACING)
#define TRACKS_PATH_CLASS
#endif

// A stored photon of an L S+ path goes to the camera where light tracing takes its surface;
// elsewhere it is stored as scattered light, for the gather.
// A mix's leaf is picked as the eye path picks it, by a number of its own (drawn only on a
// mix, so that other scenes keep their random streams); a thin lens's point by two more.
#ifdef HAS_DEPTH_OF_FIELD
#define LENS_NUMBERS vec2(rng_next(rng), rng_next(rng))
#else
#define LENS_NUMBERS vec2(0.0)
#endif
#define LIGHT_TRACE(s, dir, flux, path_bounces)                                        \
    if (path_class == LIGHT_PATH_SPECULAR_CHAIN) {                                     \
        if (light_traceable(s)) {                                                      \
            float u_leaf = material_kind(s.material) == MATERIAL_MIX ? rng_next(rng) : 0.5; \
            splat_to_camera(s, dir, flux, path_bounces, u_leaf, LENS_NUMBERS, rng);    \
        } else {                                                                       \
            stored_class = LIGHT_PATH_SCATTERED;                                       \
        }                                                                              \
    }

// The path's class (common/pass_films.glsl) after a bounce that scattered it: a caustic stays
// one, a smooth bounce makes one. Light tracing's classes: common/light_splats.glsl.
#if defined(HAS_LIGHT_TRACING)
// A followed lobe keeps a path light tracing's where it is sharp, roughness up to this (GGX
// alpha 0.01: a caustic spread by about half a degree): behind a rougher one (frosted glass,
// a glossy metal) the caustic is spread and dim, a few photons a pixel, which splatted one by
// one are salt-like noise where the gather's disc smooths them (docs/light_tracing.md).
const float LIGHT_TRACED_ROUGHNESS = 0.1;
bool light_traced_lobe(Shading sh) { return sh.roughness <= LIGHT_TRACED_ROUGHNESS; }
#define PATH_SCATTERED(smooth_bounce) \
    path_class = light_path_after_scatter(path_class, (smooth_bounce) && light_traced_lobe(sh))
#elif defined(PASS_PHOTON_SPLIT)
#define PATH_SCATTERED(smooth_bounce) \
    path_class = max(path_class, (smooth_bounce) ? PHOTON_PATH_CAUSTIC : PHOTON_PATH_INDIRECT)
#else
#define PATH_SCATTERED(smooth_bounce)
#endif

// The warm-up's steps (pass_stages.cpp, warm_up_photon_paths): the paths advance towards
// their stationary state before a film's first pass; the paths they start are not counted
// and nothing reaches the film (their stored photons are never gathered: the next step
// overwrites them).
uniform uint u_warm_up;
#ifdef VCM_MERGING
uniform uint u_merge_slots;  // the light vertices' slots a path may fill (vcm_merge_slots)
#endif

RNG_STATE load_photon_rng(uint i, uint state_index) {
#ifdef RNG_PCG
    // Streams after the whole frame's pixels: every tile of a frame traces the same photons.
    return rng_load(frame_pixels + i);
#else
    return rng_load(state_index);
#endif
}

// Whether a photon is stored at this hit: wherever a visible point can gather it (a lobe
// rougher than the threshold; on a mix, any rough leaf, as the eye path picks its own), and
// with light sampling not straight from the light (direct light, which light sampling
// counts instead).
bool stores_photon(int material, Shading sh, uint path_bounces) {
#ifdef HAS_ROUGH_LOBES
    bool store = material_kind(material) == MATERIAL_MIX ? material_has_rough_leaf(material)
                                                         : bsdf_has_rough_lobe(sh);
#else
    bool store = bsdf_has_rough_lobe(sh);
#endif
#ifdef LIGHT_LINKING
    photon_link_absorbed = !photon_link_lands(material, store);
    store = store && !photon_link_absorbed;
#endif
#ifdef DIRECT_LIGHT_SAMPLED
    store = store && (path_bounces & BOUNCES_SCATTERED) != 0u;
#endif
    return store;
}

// The stored photon at s: its position with an independent random key for the stochastic
// hash, and its flux with the side word of the true surface (the gather reads the visible
// point's).
void photon_at(Surface s, Shading sh, vec3 dir, vec3 flux, inout RNG_STATE rng,
               out vec4 position_key, out vec4 stored) {
    uint key = 0x01000000u +
               ((uint(rng_next(rng) * 65536.0) << 13) ^ uint(rng_next(rng) * 536870912.0));
    position_key = vec4(s.position, uintBitsToFloat(key));
    stored = vec4(flux, photon_side_word(dot(dir, s.geometric_normal) < 0.0
                                             ? s.geometric_normal
                                             : -s.geometric_normal));
#ifdef HAS_NORMAL_MAP
    // The gather's f(wo, wi) times |wi.ns| / |wi.ng|, which turns the photons' density (per
    // area of the true surface) into the shading normal's cosine: folded into the stored
    // flux, since the gather multiplies the two.
    stored.xyz *= shading_cosine_ratio(-dir, sh.n, s.geometric_normal);
#endif
}

// What a photon carries on after the sampled direction wi beyond its sample's weight: with
// a normal map, Veach's adjoint BSDF for shading normals (thesis, eq. 5.17),
// |wo.ns| |wi.ng| / (|wo.ng| |wi.ns|); 1 otherwise.
float adjoint_shading_factor(vec3 wo, vec3 wi, Shading sh, vec3 ng) {
#ifdef HAS_NORMAL_MAP
    return shading_cosine_ratio(wo, sh.n, ng) / max(shading_cosine_ratio(wi, sh.n, ng), 1.0e-6);
#else
    return 1.0;
#endif
}

// The bounce word's kind of a photon's scatter: through a cut-out it has not scattered
// (still direct light).
uint photon_bounce_kind(Shading sh, vec3 wo, vec3 wi, vec3 ng, vec3 u_dir) {
    return sh.kind == MATERIAL_TRANSPARENT
               ? BOUNCE_NONE : bounce_kind(wo, wi, ng, bsdf_sample_is_diffuse(sh, wo, u_dir));
}

#ifdef VCM_LIGHT_TRACING
#include "common/vcm_light_paths.glsl"
#else
// One bounce of the path in record i (its origin, direction, flux and bounce words in
// common/records.glsl): the photon it stores at the surface it meets, if any, and where it
// goes on. `bounces` counts the surfaces met so far: a path ends at its (max_bounces + 1)th,
// the last that a path within the total can store a photon on (its first scatter is not
// counted: common/bounces.glsl). The bounce word `path_bounces` is BOUNCES_SCATTERED once
// the path has scattered (specular or diffuse), not while it comes straight from the light,
// and holds its later scatters by kind. Its state stays in main's locals (as the eye
// stage's does: passed as a struct it cost 1.5x there).
void main() {
    uint i = thread_index();
    if (i >= photon_threads) return;
    uint state_index = image_width * image_height + i;
    RNG_STATE rng = load_photon_rng(i, state_index);
    vec4 p0 = photon_path_record(i, PHOTON_PATH_ORIGIN);
    vec3 origin = p0.xyz;
    float bounces = p0.w;
    vec3 dir = photon_path_record(i, PHOTON_PATH_DIR).xyz;
    uint path_bounces = uint(photon_path_record(i, PHOTON_PATH_DIR).w);
    vec3 flux = photon_path_record(i, PHOTON_PATH_FLUX).xyz;
    load_photon_group(i);  // with light groups: the path's (common/sppm_buffers.glsl)
    float path_class = 0.0;  // PHOTON_PATH_DIRECT, LIGHT_PATH_UNSCATTERED (TRACKS_PATH_CLASS)
#ifdef TRACKS_PATH_CLASS
    path_class = photon_path_class_of(photon_path_record(i, PHOTON_PATH_FLUX).w);
#endif
#ifdef ESTIMATOR_PPPM
    // Passes are independent (Knaus and Zwicker 2011): every path starts at a pass's first
    // photon step and is traced in its steps; one that has ended waits for the next pass.
    if (photon_step == 0u) {
        bounces = -1.0;
    } else if (bounces < 0.0) {
        store_photon_record(i, PHOTON_FLUX, vec4(0.0));
        return;
    }
#endif
    if (bounces < 0.0) {
        emit_photon(rng, origin, dir, flux);
        bounces = 0.0;
        path_bounces = 0u;
        path_class = 0.0;
        if (u_warm_up == 0u) atomicAdd(pass_emitted, 1u);
    }

    vec4 stored = vec4(0.0);  // w: the side word (sppm_buffers.glsl) when a photon is stored
    vec4 position_key = vec4(0.0);
    vec3 incoming = vec3(0.0);
    float stored_class = path_class;  // the class the photon arrives with
    uint stored_bounces = path_bounces;  // the bounce word the photon arrives with
    Hit hit = closest_hit(make_ray(origin, dir));
    if (hit.triangle < 0) {
        bounces = -1.0;  // left the scene: a new path next pass
    } else {
        Surface s = surface_at(make_ray(origin, dir), hit);
#ifdef HAS_ABSORPTION
        // This pass's one segment ran inside an absorbing object if it left through its back:
        // the flux it carries on (and stores here) is what got through.
        flux *= segment_transmittance(s.material, dot(dir, s.geometric_normal) < 0.0, origin,
                                      s.position);
#endif
        int kind = material_kind(s.material);
        bounces += 1.0;
        int flags = material_flags(s.material);
        bool shadowless = (flags & MATERIAL_CASTS_NO_SHADOW) != 0;
        if ((flags & MATERIAL_LIGHT_SURFACE) != 0 ||
            (shadowless && kind != MATERIAL_DIFFUSE) || PHOTON_LINK_PASSES(s.material)) {
            // Lights cast no shadow: go on through, next pass.
            origin = offset_origin(s.position, s.geometric_normal, dir);
            if (bounces > float(max_bounces)) bounces = -1.0;
        } else {
            // Stored where a visible point gathers it; on by the material's sample and RR.
            Shading sh = shading_at(s.material, s.normal, s.geometric_normal, texture_point(s),
                                    s.vertex_color, -dir, rng_next(rng));
            if (stores_photon(s.material, sh, path_bounces)) {
                photon_at(s, sh, dir, flux, rng, position_key, stored);
                incoming = -dir;
#ifdef HAS_LIGHT_TRACING
                if (u_warm_up == 0u) { LIGHT_TRACE(s, dir, flux, path_bounces); }
#endif
            }
            vec3 u_dir = vec3(rng_next(rng), rng_next(rng), rng_next(rng));
            vec3 wi, w;
            // Where the photon goes on: a leaf chosen by what the mix's parts scatter (its own
            // draw; the leaf above decided only whether it is stored).
            float mix_weight = 1.0;
#ifdef HAS_ROUGH_LOBES
            if (material_kind(s.material) == MATERIAL_MIX)
                sh = shading_at_by_scatter(s.material, s.normal, s.geometric_normal, texture_point(s),
                                           s.vertex_color, -dir, rng_next(rng), mix_weight);
#endif
            if (shadowless) {
                // Casting no shadow: lit where the photon lands, which then goes on unchanged.
                origin = offset_origin(s.position, s.geometric_normal, dir);
                if (bounces > float(max_bounces)) bounces = -1.0;
            } else if (bounces > float(max_bounces) || photon_link_absorbed ||
                       !bsdf_sample(sh, -dir, u_dir, true, wi, w)) {
                bounces = -1.0;
            } else {
                w *= mix_weight;
                float q = min(1.0, max_component(w) / photon_refraction_factor(sh, wi));
                if (rng_next(rng) >= q) {
                    bounces = -1.0;
                } else {
                    flux *= w / q;
                    flux *= adjoint_shading_factor(-dir, wi, sh, s.geometric_normal);
                    // Through a cut-out the photon has not scattered: its class stays.
                    if (sh.kind != MATERIAL_TRANSPARENT)
                        PATH_SCATTERED(bsdf_sample_is_smooth(sh, -dir, u_dir));
                    wi = on_the_lobes_side(wi, sh, s.geometric_normal);
                    // A path no visible point may gather within the limits ends.
                    uint kind_now = photon_bounce_kind(sh, -dir, wi, s.geometric_normal, u_dir);
                    path_bounces = photon_bounces_scattered(path_bounces, kind_now);
                    if (!photon_bounces_useful(path_bounces)) bounces = -1.0;
                    dir = wi;
                    origin = offset_origin(s.position, s.geometric_normal, dir);
                }
            }
        }
    }

    store_photon_path_record(i, PHOTON_PATH_ORIGIN, vec4(origin, bounces));
    store_photon_path_record(i, PHOTON_PATH_DIR, vec4(dir, float(path_bounces)));
    store_photon_path_record(i, PHOTON_PATH_FLUX, vec4(flux, photon_path_word(path_class)));
    store_photon_record(i, PHOTON_INCOMING,
                        vec4(incoming, photon_record_word(stored_class, stored_bounces)));
    store_photon_record(i, PHOTON_POSITION, position_key);
    store_photon_record(i, PHOTON_FLUX, stored);
    rng_store(state_index, rng);
    atomicAdd(pass_rays, 1u);
}
#endif
