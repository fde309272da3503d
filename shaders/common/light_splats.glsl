// Light tracing's film (HAS_LIGHT_TRACING; common/light_tracing.glsl connects the photons to
// the camera). Photons splat to any pixel, so a pass's splats are summed with atomics: in
// 64-bit fixed point, two uint words a channel with the carry propagated exactly, so that the
// pass's sum is the same whatever order the threads add in (farm and multi-GPU merges stay
// bit-exact, as with the rest of the film). light_splats.comp folds each pass's integers into
// a compensated float sum at the end of the pass; resolve_film.comp divides that by the
// photon paths emitted, as it divides SPPM's tau.
//
// Per pixel, LIGHT_SPLAT_WORDS uints: the pass's (lo, hi) words for r, g and b; then the
// float bits of the sum (rgb) and of its Kahan compensation (rgb). 48 bytes, no more than
// the smallest visible point, so that image tiles planned by those fit this buffer too. The
// buffer is declared where USES_LIGHT_SPLATS is defined (GL counts every declared block); the
// path classes below are for every stage.
#ifndef LIGHT_SPLATS_GLSL
#define LIGHT_SPLATS_GLSL
#include "common/bindings.glsl"
#include "common/records.glsl"

#ifdef USES_LIGHT_SPLATS

layout(std430, binding = BINDING_LIGHT_SPLATS) coherent buffer LightSplats { uint light_splats[]; };

const uint LIGHT_SPLAT_SUM = 6u;           // the float sum's first word
const uint LIGHT_SPLAT_COMPENSATION = 9u;  // its compensation's
const float TWO_POW_32 = 4294967296.0;
// A single splat is clamped below 2^62 units, so that a pass's sum of a pixel stays within
// 64 bits for 2^30 splats even at the clamp (light_splat_unit in native/render/camera_frame.cpp
// puts a photon at the scene's radius near 2^40 units).
const float LIGHT_SPLAT_MAX_UNITS = 4.0e18;

// Adds `units` (>= 0, finite) to the 64-bit word pair at k: the low word's carry goes into
// the high word in the same add, so the pair's final value is the exact sum.
void add_fixed_point(uint k, float units) {
    uint hi = 0u, lo;
    if (units < TWO_POW_32 - 1.0) {
        lo = uint(units + 0.5);  // to the nearest unit
    } else {
        hi = uint(floor(units / TWO_POW_32));
        lo = uint(max(units - float(hi) * TWO_POW_32, 0.0));
    }
    uint carry = 0u;
    if (lo != 0u) {
        uint before = atomicAdd(light_splats[k], lo);
        uaddCarry(before, lo, carry);
    }
    if (hi + carry != 0u) atomicAdd(light_splats[k + 1u], hi + carry);
}

// One splat of `value` (radiance times pixel area, per photon emitted) into pixel i.
// Anything not finite and positive is dropped, so that no NaN or infinity reaches the film.
void light_splat_add(uint i, vec3 value) {
    vec3 units = value / light_splat_unit;
    for (int c = 0; c < 3; ++c) {
        float u = units[c];
        if (!(u > 0.0) || isinf(u) || isnan(u)) continue;
        add_fixed_point(i * LIGHT_SPLAT_WORDS + 2u * uint(c), min(u, LIGHT_SPLAT_MAX_UNITS));
    }
}

// The pass's fixed-point sum of pixel i, in splat units times light_splat_unit.
vec3 light_splat_pass(uint i) {
    uint k = i * LIGHT_SPLAT_WORDS;
    vec3 v;
    for (int c = 0; c < 3; ++c)
        v[c] = float(light_splats[k + 2u * uint(c) + 1u]) * TWO_POW_32 +
               float(light_splats[k + 2u * uint(c)]);
    return v * light_splat_unit;
}

vec3 light_splat_word3(uint k) {
    return uintBitsToFloat(uvec3(light_splats[k], light_splats[k + 1u], light_splats[k + 2u]));
}

// The splats of every pass so far (radiance times pixel area), before the division by the
// photons emitted.
vec3 light_splat_sum(uint i) {
    return light_splat_word3(i * LIGHT_SPLAT_WORDS + LIGHT_SPLAT_SUM);
}

#ifdef LIGHT_GROUPS
// Light groups (common/light_groups.glsl): after the frame's pixels, one more block of
// LIGHT_SPLAT_WORDS a pixel per group, where each splat goes as well, by the group of the
// photon's emitter. Each group's integers are the sum of its own splats, exactly, so the
// groups and the splats of no group add up to Combined's integers; the host reads the
// groups' float sums back (render_passes.cpp, add_light_group_splats).
uint light_splat_group_word(uint i, uint group) {
    return ((group + 1u) * image_width * image_height + i) * LIGHT_SPLAT_WORDS;
}

// light_splat_add's splat into the group of this code (0: none), the same units.
void light_splat_group_add(uint i, uint code, vec3 value) {
    if (code == 0u) return;
    uint k = light_splat_group_word(i, code - 1u);
    vec3 units = value / light_splat_unit;
    for (int c = 0; c < 3; ++c) {
        float u = units[c];
        if (!(u > 0.0) || isinf(u) || isnan(u)) continue;
        add_fixed_point(k + 2u * uint(c), min(u, LIGHT_SPLAT_MAX_UNITS));
    }
}

// light_splat_pass of the words from k.
vec3 light_splat_pass_at(uint k) {
    vec3 v;
    for (int c = 0; c < 3; ++c)
        v[c] = float(light_splats[k + 2u * uint(c) + 1u]) * TWO_POW_32 +
               float(light_splats[k + 2u * uint(c)]);
    return v * light_splat_unit;
}
#endif

// The film's pixel area: on the z = -1 plane (perspective) or in world units (orthographic),
// as the camera's importance is normalised (common/light_tracing.glsl).
float light_splat_pixel_area() {
    return 4.0 * film_half_extent.x * film_half_extent.y /
           (float(image_width) * float(image_height));
}
#endif

// The photon path class light tracing owns (HAS_LIGHT_TRACING, where the light split's passes
// are off: native/render/scene_features.cpp). It rides in the class field of the path's
// flux.w and of the stored photon's record word (common/sppm_buffers.glsl), whose values 0-2
// are the split's (common/pass_films.glsl): unscattered, scattered otherwise, or L S+: every
// scatter so far smooth (mirror, glass), at least one. Unlike the split's caustic class it
// does not survive a later diffuse or rough bounce.
const float LIGHT_PATH_UNSCATTERED = 0.0;
const float LIGHT_PATH_SCATTERED = 1.0;
const float LIGHT_PATH_SPECULAR_CHAIN = 3.0;

float light_path_after_scatter(float path_class, bool smooth_bounce) {
    bool chain = path_class == LIGHT_PATH_UNSCATTERED || path_class == LIGHT_PATH_SPECULAR_CHAIN;
    return smooth_bounce && chain ? LIGHT_PATH_SPECULAR_CHAIN : LIGHT_PATH_SCATTERED;
}

#ifdef USES_PHOTONS
// The partition of the L S+ D E paths: light tracing splats every L S+ photon on a surface
// the camera sees directly (common/light_tracing.glsl), so a visible point with no scatter
// before it (eye word 0: camera rays count every mirror and glass bounce) leaves those
// photons out, and nothing is counted twice. Every other path stays with the gather.
bool light_traced(uint p, uint eye_bounces) {
    return eye_bounces == 0u && photon_class(p) == uint(LIGHT_PATH_SPECULAR_CHAIN);
}
#endif

#endif
