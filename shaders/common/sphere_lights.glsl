// Point and spot lights of a radius, seen in mirrors and through glass (SPHERE_LIGHT_RECORDS):
// as in Cycles, a light of radius r is a sphere that specular rays can hit. Its radiance is
// the one its light samples and photons assume: intensity I over its disc, I / (pi r^2),
// with I = P / 4 pi for a point light (L = P / (4 pi^2 r^2), common/light_sampling.glsl)
// and the spot's intensity times its cone and smooth edge towards the viewer. Camera rays
// do not see them (they do not in Cycles either).
//
// The point, spot and sun lights' records are SPHERE_LIGHT_RECORDS from SPHERE_LIGHT_FIRST
// in the emitter table (native/render/emitters.cpp).
#ifndef SPHERE_LIGHTS_GLSL
#define SPHERE_LIGHTS_GLSL

#include "common/emitters.glsl"
#include "common/light_linking.glsl"

#ifdef LIGHT_GROUPS
// The light group code of the sphere light hit_sphere_light found last (light_groups.glsl).
uint sphere_light_group_code = 0u;
#endif

#if (defined(GLOSSY_LIGHT_SAMPLES) || defined(LIGHT_LINKING)) && !defined(VCM_MIS)
// The record hit_sphere_light found last (common/glossy_light_samples.glsl weighs its light;
// the eye path's shadow linking reads its set).
uint sphere_light_record = 0u;
#endif

// The nearest sphere light the ray meets before origin + t_max ray_dir: true, with its
// radiance. With links, only those whose light reaches the eye path's receiver.
bool hit_sphere_light(vec3 origin, vec3 ray_dir, float t_max, out vec3 radiance) {
    radiance = vec3(0.0);
    bool found = false;
    float length_dir = length(ray_dir);
    vec3 dir = ray_dir / length_dir;
    float nearest = t_max * length_dir;
    for (uint k = SPHERE_LIGHT_FIRST; k < SPHERE_LIGHT_FIRST + SPHERE_LIGHT_RECORDS; ++k) {
        vec4 a = emitter_record(k, EMITTER_A), b = emitter_record(k, EMITTER_B);
        vec4 c = emitter_record(k, EMITTER_C);
        int kind = floatBitsToInt(a.w) & EMITTER_KIND_MASK;
        float r = kind == EMITTER_POINT ? b.w : (kind == EMITTER_SPOT ? c.y : 0.0);
        if (r <= 0.0) continue;
#ifdef LIGHT_LINKING
        // Not there for the eye path's receiver (common/light_linking.glsl).
        if (!eye_link_reaches(uint(floatBitsToInt(a.w)) >> EMITTER_LINK_SHIFT)) continue;
#endif
        // |origin + t dir - centre| = r, dir of unit length; the nearer root outside.
        vec3 oc = origin - a.xyz;
        float half_b = dot(oc, dir);
        float cc = dot(oc, oc) - r * r;
        if (cc <= 0.0) continue;  // inside it: a sphere light emits outwards only
        float disc = half_b * half_b - cc;
        if (disc < 0.0) continue;
        float t = -half_b - sqrt(disc);
        if (t <= 0.0 || t >= nearest) continue;
        vec3 power = emitter_record(k, EMITTER_POWER).rgb;
        vec3 l;
        if (kind == EMITTER_POINT) {
            l = power / (4.0 * PI * PI * r * r);
        } else {
            // The record holds the hard cone's power P Omega / 4 pi: I = that / Omega.
            float solid_angle = 2.0 * PI * (1.0 - b.w);
            float attenuation = spot_attenuation(b.xyz, -dir, b.w, c.x);
            if (spot_cosine_falloff(c.z)) attenuation *= max(0.0, dot(b.xyz, -dir));
            l = solid_angle > 0.0 ? power * (attenuation / (solid_angle * PI * r * r))
                                  : vec3(0.0);
        }
        nearest = t;
        radiance = l;
        found = true;
#ifdef LIGHT_GROUPS
        sphere_light_group_code = emitter_group_code(k);
#endif
#if defined(VCM_MIS) || defined(GLOSSY_LIGHT_SAMPLES) || defined(LIGHT_LINKING)
        sphere_light_record = k;
#endif
    }
    return found;
}

#endif
