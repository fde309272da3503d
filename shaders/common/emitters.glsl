// Starting photon paths at the lights. An emitter is picked with probability proportional
// to its power (the cumulative table lives in each record's c.w), then a position and a
// direction are sampled; the flux carried is the sample's contribution over its pdf, so that
// the photons' mean flux is the total emitted power (see native/render/emitters.h).
#ifndef EMITTERS_GLSL
#define EMITTERS_GLSL

#include "common/scene_buffers.glsl"
#include "common/sampling.glsl"

uint pick_emitter(float u) {
    uint lo = 0u, hi = pass_info.w - 1u;
    while (lo < hi) {
        uint mid = (lo + hi) / 2u;
        if (u < emitters[4u * mid + 2u].w) hi = mid;
        else lo = mid + 1u;
    }
    return lo;
}

// Blender's spot cone with its smooth edge (Cycles' spot_attenuation).
float spot_attenuation(vec3 axis, vec3 dir, float cos_half, float smooth_width) {
    float c = dot(axis, dir);
    if (c <= cos_half) return 0.0;
    float t = c - cos_half;
    return t < smooth_width ? smoothstep(0.0, smooth_width, t) : 1.0;
}

// Samples a photon's origin, direction and flux; `ng` is the surface normal at the origin
// (zero for points and distant lights).
void emit_photon(inout RNG_STATE rng, out vec3 origin, out vec3 dir, out vec3 flux) {
    uint k = pick_emitter(rng_next(rng));
    vec4 a = emitters[4u * k + 0u];
    vec4 b = emitters[4u * k + 1u];
    vec4 c = emitters[4u * k + 2u];
    vec4 d = emitters[4u * k + 3u];
    int kind = floatBitsToInt(a.w);
    float u1 = rng_next(rng), u2 = rng_next(rng);
    float u3 = rng_next(rng), u4 = rng_next(rng);
    vec3 power = d.rgb / d.w;  // d.rgb holds the emitter's power: flux / pick probability
#ifdef HAS_TRIANGLE_EMITTERS
    if (kind == EMITTER_TRIANGLE) {
        // Uniform on the triangle, cosine-weighted about its front face: flux = pi L A / p.
        vec2 bc = sample_triangle(u1, u2);
        vec3 p = a.xyz + bc.x * (b.xyz - a.xyz) + bc.y * (c.xyz - a.xyz);
        vec3 n = normalize(cross(b.xyz - a.xyz, c.xyz - a.xyz));
        dir = sample_cosine_hemisphere(n, u3, u4);
        origin = offset_origin(p, n, dir);
        flux = power;
        return;
    }
#endif
#ifdef HAS_POINT_LIGHTS
    if (kind == EMITTER_POINT) {
        origin = a.xyz;
        dir = sample_sphere(u1, u2);
        flux = power;
        return;
    }
#endif
#ifdef HAS_SPOT_LIGHTS
    if (kind == EMITTER_SPOT) {
        // Uniform in the cone; the smooth edge weights the flux (its power in d assumes a
        // hard edge, the cone's solid angle times the intensity).
        origin = a.xyz;
        dir = sample_cone(b.xyz, b.w, u1, u2);
        flux = power * spot_attenuation(b.xyz, dir, b.w, c.x);
        return;
    }
#endif
#if defined(HAS_SUN_LIGHTS) || defined(HAS_ENVIRONMENT)
    if (kind == EMITTER_SUN || kind == EMITTER_ENVIRONMENT) {
        // Distant light through the scene's bounding disc facing the light.
        dir = kind == EMITTER_SUN ? b.xyz : -sample_sphere(u3, u4);
        vec3 t, bt;
        orthonormal_basis(dir, t, bt);
        vec2 q = sample_disc(u1, u2) * scene_sphere.w;
        origin = scene_sphere.xyz - dir * (1.01 * scene_sphere.w) + q.x * t + q.y * bt;
        flux = power;
        return;
    }
#endif
    origin = vec3(0.0);
    dir = vec3(0.0, 0.0, 1.0);
    flux = vec3(0.0);
}

#endif
