// Starting photon paths at the emitters (docs/architecture.md, "Words": the lights' records,
// emissive triangles, the world). An emitter is picked with probability proportional
// to its power (the cumulative table lives in each record's c.w), then a position and a
// direction are sampled; the flux carried is the sample's contribution over its pdf, so that
// the photons' mean flux is the total emitted power (see native/render/emitters.h).
#ifndef EMITTERS_GLSL
#define EMITTERS_GLSL

#include "common/scene_buffers.glsl"
#include "common/sampling.glsl"
#include "common/surface.glsl"
#include "common/environment.glsl"
#include "common/textures.glsl"

uint pick_emitter(float u) {
    uint lo = 0u, hi = emitter_count - 1u;
    while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        if (u < emitter_record(mid, EMITTER_C).w) hi = mid;
        else lo = mid + 1u;
    }
    return lo;
}

// A spot record's c.z: 1 for Blender 3.x's cosine falloff towards the axis, + 2 where light
// samples take the disc facing the lit point (Light::facing_disc).
bool spot_cosine_falloff(float code) { return mod(code, 2.0) > 0.5; }
bool spot_facing_disc(float code) { return code > 1.5; }

// Blender's spot cone with its smooth edge (Cycles' spot_attenuation).
float spot_attenuation(vec3 axis, vec3 dir, float cos_half, float smooth_width) {
    float c = dot(axis, dir);
    if (c <= cos_half) return 0.0;
    float t = c - cos_half;
    return t < smooth_width ? smoothstep(0.0, smooth_width, t) : 1.0;
}

// A triangle emitter's b.w (native/render/emitters.cpp): 0 or 1 for one or two sides, or,
// for a textured emitter, -(1 + 2 t + two sided), t its packed triangle.
bool triangle_emitter_two_sided(float bw) {
#ifdef HAS_EMISSION_TEXTURE
    if (bw < 0.0) return ((int(-bw) - 1) & 1) != 0;
#endif
    return bw > 0.5;
}

// What a point (barycentrics bc of the record's b and c) of a triangle emitter radiates
// over what its record holds: the texel of its material's emission texture there, else 1.
// The record holds the untextured power and is picked by the textured mean, so a photon's
// or light sample's weight, texel / pick probability, is right in expectation.
vec3 triangle_emitter_texel(float bw, vec2 bc) {
#if defined(HAS_EMISSION_TEXTURE) && defined(HAS_TEXTURES)
    if (bw < 0.0) {
        int t = (int(-bw) - 1) >> 1;
        int k = floatBitsToInt(material_record(floatBitsToInt(triangles[3 * t].w),
                                                    MATERIAL_EMISSION_TEXTURE).x);
        vec4 uv01 = vertex_uvs[2 * t + 0];
        vec2 uv2 = vertex_uvs[2 * t + 1].xy;
        vec3 p0 = triangles[3 * t].xyz;
        vec3 position = p0 + bc.x * (triangles[3 * t + 1].xyz - p0) +
                        bc.y * (triangles[3 * t + 2].xyz - p0);
        vec2 uv = uv01.xy + bc.x * (uv01.zw - uv01.xy) + bc.y * (uv2 - uv01.xy);
        if (k >= 0) return sample_texture(k, TexturePoint(uv, position)).rgb;
    }
#endif
    return vec3(1.0);
}

#ifdef HAS_EMITTER_MIS
// The emitter record of packed triangle t, or -1: the map after the records
// (native/render/emitters.h, append_triangle_map), four ints to a vec4.
int triangle_emitter(int t) {
    return floatBitsToInt(emitters[EMITTER_VEC4 * emitter_count + uint(t >> 2)][t & 3]);
}
#endif

// Samples a photon's origin, direction and flux; `ng` is the surface normal at the origin
// (zero for points and distant lights).
void emit_photon(inout RNG_STATE rng, out vec3 origin, out vec3 dir, out vec3 flux) {
    uint k = pick_emitter(rng_next(rng));
    vec4 a = emitter_record(k, EMITTER_A);
    vec4 b = emitter_record(k, EMITTER_B);
    vec4 c = emitter_record(k, EMITTER_C);
    vec4 d = emitter_record(k, EMITTER_POWER);
    int kind = floatBitsToInt(a.w) & EMITTER_KIND_MASK;
#if defined(LIGHT_GROUPS) && defined(USES_PHOTON_PATHS)
    photon_group_code = emitter_group_code(k);  // the path carries its emitter's group
#endif
#if defined(LIGHT_LINKING) && defined(USES_PHOTON_PATHS)
    photon_link_code = emitter_link_set(k) + 1u;  // and its link set, until it lands
#endif
    float u1 = rng_next(rng), u2 = rng_next(rng);
    float u3 = rng_next(rng), u4 = rng_next(rng);
    vec3 power = d.rgb / d.w;  // d.rgb holds the emitter's power: flux / pick probability
#ifdef HAS_TRIANGLE_EMITTERS
    if (kind == EMITTER_TRIANGLE) {
        // Uniform on the triangle, cosine-weighted about its front face: flux = pi L A / p.
        // A two-sided emitter (b.w = 1, power 2 pi L A) picks either face evenly.
        vec2 bc = sample_triangle(u1, u2);
        vec3 p = a.xyz + bc.x * (b.xyz - a.xyz) + bc.y * (c.xyz - a.xyz);
        vec3 n = triangle_normal(a.xyz, b.xyz, c.xyz);
        if (triangle_emitter_two_sided(b.w)) {
            n = u3 < 0.5 ? -n : n;
            u3 = u3 < 0.5 ? 2.0 * u3 : 2.0 * u3 - 1.0;
        }
        dir = sample_cosine_hemisphere(n, u3, u4);
        origin = offset_origin(p, n, dir);
        flux = power * triangle_emitter_texel(b.w, bc);
        return;
    }
#endif
#ifdef HAS_POINT_LIGHTS
    if (kind == EMITTER_POINT) {
        // A sphere of radius b.w radiating evenly: a uniform point on it, a cosine-weighted
        // direction about its normal (flux = power / p); a point light when b.w = 0.
        vec3 n = sample_sphere(u1, u2);
        origin = a.xyz + b.w * n;
        dir = b.w > 0.0 ? sample_cosine_hemisphere(n, u3, u4) : n;
        flux = power;
        return;
    }
#endif
#ifdef HAS_SPOT_LIGHTS
    if (kind == EMITTER_SPOT) {
        // Uniform in the cone; the smooth edge (and Blender 3.x's cosine falloff, c.z = 1)
        // weights the flux (its power in d assumes a hard edge, the cone's solid angle times
        // the intensity). A radius c.y spreads the origins over a disc facing the axis.
        vec3 t, bt;
        orthonormal_basis(b.xyz, t, bt);
        vec2 q = c.y * sample_disc(u3, u4);
        origin = a.xyz + q.x * t + q.y * bt;
        dir = sample_cone(b.xyz, b.w, u1, u2);
        flux = power * spot_attenuation(b.xyz, dir, b.w, c.x);
        if (spot_cosine_falloff(c.z)) flux *= dot(b.xyz, dir);
        return;
    }
#endif
#if defined(HAS_SUN_LIGHTS) || defined(HAS_ENVIRONMENT)
    if (kind == EMITTER_SUN || kind == EMITTER_ENVIRONMENT) {
        // Distant light through the scene's bounding disc facing the light: the sun from
        // within its angular radius (cos in b.w), the world by its radiance.
        flux = power;
        if (kind == EMITTER_SUN) {
            dir = b.w < 1.0 ? sample_cone(b.xyz, b.w, u3, u4) : b.xyz;
        } else {
#ifdef HAS_ENVIRONMENT_MAP
            // flux = L(w) pi r^2 / (pdf(w) p_pick); power = pi r^2 * integral of L.
            float pdf;
            vec3 from = sample_environment(u3, u4, rng_next(rng), rng_next(rng), pdf);
            dir = -from;
            float disc = PI * scene_radius * scene_radius;
            flux = pdf > 0.0 ? environment_radiance(from) * (disc / (pdf * d.w)) : vec3(0.0);
#else
            dir = -sample_sphere(u3, u4);
#endif
        }
        vec3 t, bt;
        orthonormal_basis(dir, t, bt);
        vec2 q = sample_disc(u1, u2) * scene_radius;
        origin = scene_center - dir * (1.01 * scene_radius) + q.x * t + q.y * bt;
        return;
    }
#endif
    origin = vec3(0.0);
    dir = vec3(0.0, 0.0, 1.0);
    flux = vec3(0.0);
}

#endif
