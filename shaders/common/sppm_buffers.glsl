// SPPM state on the GPU (mirrored in native/render/gpu_layout.h).
#ifndef SPPM_BUFFERS_GLSL
#define SPPM_BUFFERS_GLSL
#include "common/bindings.glsl"
#include "common/records.glsl"

// The generators keep their state at BINDING_RNG_STATES:
// pixels first, then photon threads.
#include "common/rng.glsl"

// Pass counters; 64-bit totals are kept as (lo, hi) pairs with carry by end_pass.comp.
layout(std430, binding = BINDING_COUNTERS) coherent buffer Counters {
    uint cell_size_bits;    // hash cell size in use this pass (float bits)
    uint max_radius_bits;   // largest radius after this pass's update (float bits; atomicMax)
    uint pass_emitted;      // photon paths started this pass
    uint pass_rays;         // rays traced this pass
    uint emitted_lo, emitted_hi;
    uint rays_lo, rays_hi;
};

// GL guarantees only 16 storage blocks per compute program, and drivers count every
// declared one, so each stage declares just the groups it uses, by defining before its
// includes: USES_PIXEL_STATE (visible points, statistics, direct light), USES_PHOTON_PATHS,
// USES_PHOTONS, USES_HASH (and USES_EMITTERS in common/scene_buffers.glsl).

#ifdef USES_PIXEL_STATE
// Visible points, 4 vec4 per pixel: what the gather needs to evaluate f(wo, wi), written by
// eye_trace.comp and read by gather.comp (common/visible_points.glsl names the fields).
layout(std430, binding = BINDING_VISIBLE_POINTS) buffer VisiblePoints { vec4 visible_points[]; };

// Progressive statistics, 2 per pixel: (tau.rgb, N), (R, 0, 0, 0).
layout(std430, binding = BINDING_PIXEL_STATS) buffer PixelStats { vec4 pixel_stats[]; };

// Emission seen directly, 2 per pixel: compensated (Kahan) sum and its compensation.
layout(std430, binding = BINDING_DIRECT_LIGHT) buffer DirectLight { vec4 direct_light[]; };
#endif

#ifdef USES_PHOTON_PATHS
// Photon paths, PHOTON_PATH_VEC4 per photon thread (common/records.glsl): (origin, surfaces
// met so far or -1 = start anew), (direction, the path's bounce word: common/bounces.glsl),
// (flux, path class or 0).
layout(std430, binding = BINDING_PHOTON_PATHS) buffer PhotonPaths { vec4 photon_paths[]; };
vec4 photon_path_record(uint i, uint field) { return photon_paths[PHOTON_PATH_VEC4 * i + field]; }
void store_photon_path_record(uint i, uint field, vec4 value) {
    photon_paths[PHOTON_PATH_VEC4 * i + field] = value;
}

// A path's flux.w: its class (common/pass_films.glsl) and, with light groups or links, 4 times
// the group code of the emitter it started from (common/light_groups.glsl) plus 64 times its
// link code (common/light_linking.glsl: the emitter's link set + 1 while the path carries it,
// 0 after); exact in a float.
#if defined(LIGHT_GROUPS) || defined(LIGHT_LINKING)
uint photon_group_code = 0u;  // the traced path's, set by load_photon_group or emit_photon
uint photon_link_code = 0u;
void load_photon_group(uint i) {
    uint word = uint(photon_path_record(i, PHOTON_PATH_FLUX).w) >> 2;
    photon_group_code = word & 63u;
    photon_link_code = word >> 6;
}
float photon_path_class_of(float word) { return float(uint(word) & 3u); }
float photon_path_word(float path_class) {
    return path_class + 4.0 * float(photon_group_code + 64u * photon_link_code);
}
#else
void load_photon_group(uint i) {}
float photon_path_class_of(float word) { return word; }
float photon_path_word(float path_class) { return path_class; }
#endif
#endif

#ifdef USES_PHOTONS
// Photons stored this pass, PHOTON_VEC4 per photon thread (common/records.glsl): (position,
// random key bits), (direction towards where it came from, record word), (flux, side word or
// 0 if none stored). The record word is the path class (common/pass_films.glsl, 0 without
// the light split) plus 4 times the path's bounce word on arrival (common/bounces.glsl):
// below 2^24, an exact float. Keys are normal floats (2^24 + 29 random bits) so that no
// driver may flush or canonicalise them.
layout(std430, binding = BINDING_PHOTONS) buffer Photons { vec4 photons[]; };
vec4 photon_record(uint p, uint field) { return photons[PHOTON_VEC4 * p + field]; }
void store_photon_record(uint p, uint field, vec4 value) {
    photons[PHOTON_VEC4 * p + field] = value;
}

// The side word: the true (geometric) normal of the surface a photon landed on, on the side it
// arrived from, as two 11-bit octahedral coordinates plus 1 (an integer below 2^23, exact
// in a float, never 0). The gather leaves out photons whose surface faces away from the
// visible point's (gather.comp): the light inside a closed emissive mesh, or behind a thin
// wall, lies within the radius of the points near its edges outside.
float photon_side_word(vec3 n) {
    vec3 t = n / (abs(n.x) + abs(n.y) + abs(n.z));
    vec2 o = t.z >= 0.0 ? t.xy
                        : (1.0 - abs(t.yx)) * vec2(t.x >= 0.0 ? 1.0 : -1.0, t.y >= 0.0 ? 1.0 : -1.0);
    uvec2 q = uvec2(round(clamp(o, -1.0, 1.0) * 1023.0) + 1023.0);
    return float(1u + q.x + (q.y << 11));
}

vec3 photon_side(float word) {
    uint bits = uint(word) - 1u;
    vec2 o = (vec2(float(bits & 2047u), float(bits >> 11)) - 1023.0) / 1023.0;
    vec3 t = vec3(o, 1.0 - abs(o.x) - abs(o.y));
    if (t.z < 0.0)
        t.xy = (1.0 - abs(o.yx)) * vec2(o.x >= 0.0 ? 1.0 : -1.0, o.y >= 0.0 ? 1.0 : -1.0);
    return normalize(t);
}

// The gather's tests (gather.comp, photon_on_side): a photon whose surface faces away from
// the visible point's by more than 120 degrees (cos below -0.5) is on its other side; a convex
// surface's neighbouring photons are within 60 degrees (cos above 0.5).
const float PHOTON_SIDE_MIN_COS = 0.5;
// The slack of the plane tests, in radii, where the normals agree: the side word's rounding
// (11 bits a coordinate, about 1e-3 rad) tilts a coplanar photon's heights by up to 1e-3 r.
const float PHOTON_WALL_TOLERANCE = 0.01;

#ifndef LIGHT_GROUPS
float photon_record_word(float path_class, uint bounces) {
    return float(uint(path_class) + 4u * bounces);
}

uint photon_record_bits(uint p) { return uint(photon_record(p, PHOTON_INCOMING).w); }
#else
// With light groups the word's 24 bits and the group code's 6 are the bits of a normal float
// (no driver may flush or canonicalise it): the word's low 23 in the mantissa, its top bit in
// the sign, and the exponent field 1 + 2 code (1 to 127).
#ifdef USES_PHOTON_PATHS
float photon_record_word(float path_class, uint bounces) {
    uint word = uint(path_class) + 4u * bounces;
    return uintBitsToFloat(0x00800000u | (word & 0x7FFFFFu) | ((word >> 23) << 31) |
                           (photon_group_code << 24));
}
#endif

uint photon_record_bits(uint p) {
    uint b = floatBitsToUint(photon_record(p, PHOTON_INCOMING).w);
    return (b & 0x7FFFFFu) | ((b >> 31) << 23);
}

// The group code of the emitter photon p came from (0: none).
uint photon_group_of(uint p) {
    return (floatBitsToUint(photon_record(p, PHOTON_INCOMING).w) >> 24) & 63u;
}
#endif

uint photon_class(uint p) {
    return photon_record_bits(p) & 3u;
}

uint photon_bounces(uint p) {
    return photon_record_bits(p) >> 2;
}
#endif

#ifdef USES_HASH
// Hash cells. Stochastic: (smallest key, photon count, surviving photon, 0).
// Exact: (photon count, first sorted slot, scatter cursor, 0).
layout(std430, binding = BINDING_HASH_CELLS) coherent buffer HashCells { uvec4 hash_cells[]; };

// Exact hash only: photon indices sorted by cell, then the scan's block sums.
layout(std430, binding = BINDING_HASH_SORTED) buffer HashSorted { uint hash_sorted[]; };
#endif

#endif
