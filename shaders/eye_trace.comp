// SPPM stage 1, one thread per pixel: a fresh jittered camera ray each pass, followed
// through mirrors and glass (reflection or refraction chosen by Fresnel) within Cycles'
// Light Paths limits (common/bounces.glsl). Emission seen on the way is added to the pixel's
// direct light; the first non-specular surface becomes the pixel's visible point (Hachisuka
// 2015, section 2).
layout(local_size_x = LOCAL_SIZE) in;

#define USES_PIXEL_STATE
#ifdef DIRECT_LIGHT_SAMPLED
// Light sampling at the visible point reads the emitter table; its shadow rays pass through
// area-light surfaces and objects that cast no shadow (common/light_sampling.glsl).
#define USES_EMITTERS
#ifdef HAS_SHADOWLESS_SURFACES
#define BVH_ANY_HIT_FILTER
#endif
#endif
#ifdef SPHERE_LIGHT_RECORDS
#ifndef USES_EMITTERS
#define USES_EMITTERS
#endif
#endif
#include "common/frame.glsl"
#include "common/sppm_buffers.glsl"
#include "common/sampling.glsl"
#include "common/surface.glsl"
#include "common/bsdf.glsl"
#include "common/lobes.glsl"
#include "common/environment.glsl"
#include "common/camera.glsl"
#include "common/visible_points.glsl"
// The include splicer takes a file once, wherever it first appears, #ifdef or not: the
// emitter table's functions come first, outside either feature's block.
#ifdef USES_EMITTERS
#include "common/emitters.glsl"
#endif
#ifdef DIRECT_LIGHT_SAMPLED
#include "common/light_sampling.glsl"
#endif
#ifdef SPHERE_LIGHT_RECORDS
#include "common/sphere_lights.glsl"
#endif
#include "common/compensated_sum.glsl"
#ifdef HAS_ABSORPTION
#include "common/absorption.glsl"
#endif
#include "common/pass_films.glsl"
#include "common/bounces.glsl"
#if defined(PASS_DENOISING_ALBEDO) || defined(PASS_DENOISING_NORMAL)
#define DENOISING_FEATURES
#include "common/denoising_features.glsl"
#endif

// One eye path while it is followed: its ray and throughput, the light it has met (Combined's
// sum and, with render passes, its part of the light split: emission, the world, or light
// sampled at the visible point), and the visible point it ends at.
struct EyePath {
    Ray ray;
    vec3 throughput;
    vec3 direct;
#ifdef PASS_STRIDE
    vec3 emitted, world, sampled;
    // The first surface the camera sees (Depth, Normal): Cycles' z-depth along the view axis,
    // 1e10 where the ray leaves the scene, and the normal facing the camera.
    float first_depth;
    vec3 first_normal;
    bool first_found;
#endif
#ifdef DENOISING_FEATURES
    DenoisingFeatures features;
#endif
#ifdef FILM_TRANSPARENT
    // How much of this sample leaves the scene unseen: the film's alpha is 1 - its mean.
    // The world is then not seen by such rays (Blender's Film > Transparent).
    float transparent;
    bool through_glass;  // every bounce so far a transmission through glass
#endif
#ifdef DIRECT_LIGHT_SAMPLED
    float light_pick;
    vec4 light_u;
#endif
    VisiblePoint point;  // material -1 until the path holds one
    uint rays;
    bool seen_by_camera;  // until the first specular bounce
    // The eye subpath's scatters so far (common/bounces.glsl). One past a limit, the path
    // still takes the emission (and the world) of the surface it meets next, as Cycles'
    // PATH_RAY_TERMINATE_AFTER_TRANSPARENT, and ends there: no visible point, no light sample.
    uint bounces;
    bool last_surface;
};

#ifdef PASS_STRIDE
#define ADD_LIGHT(part, value) { vec3 light_ = (value); e.direct += light_; e.part += light_; }
#else
#define ADD_LIGHT(part, value) e.direct += (value)
#endif

// A fresh jittered camera ray through pixel (x, y). The lens numbers are drawn only where
// camera_ray_at uses them (a perspective camera with HAS_DEPTH_OF_FIELD), so that every
// other camera keeps its random streams.
Ray camera_ray(uint x, uint y, inout RNG_STATE rng) {
    float jx = rng_next(rng), jy = rng_next(rng);
    vec2 lens_u = vec2(0.0);
#ifdef HAS_DEPTH_OF_FIELD
    if (orthographic == 0u) {
        lens_u.x = rng_next(rng);
        lens_u.y = rng_next(rng);
    }
#endif
    vec3 origin, dir;
    camera_ray_at(vec2(float(x) + jx, float(y) + jy), lens_u, origin, dir);
    return make_ray(origin, normalize(dir));
}

EyePath start_eye_path(uint i, inout RNG_STATE rng) {
    EyePath e;
#ifdef DIRECT_LIGHT_SAMPLED
    // The light sample's numbers come first, so that draws only some variants make (the
    // lens) do not change them: every variant of a scene renders the same image.
    e.light_pick = rng_next(rng);
    e.light_u = vec4(rng_next(rng), rng_next(rng), rng_next(rng), rng_next(rng));
#endif
    e.ray = camera_ray(i % image_width, i / image_width, rng);
    e.throughput = vec3(1.0);
    e.direct = vec3(0.0);
#ifdef PASS_STRIDE
    e.emitted = vec3(0.0);
    e.world = vec3(0.0);
    e.sampled = vec3(0.0);
    e.first_depth = 1e10;
    e.first_normal = vec3(0.0);
    e.first_found = false;
#endif
#ifdef DENOISING_FEATURES
    e.features = start_denoising_features();
#endif
#ifdef FILM_TRANSPARENT
    e.transparent = 0.0;
    e.through_glass = true;
#endif
    // No point: any unit vectors for the packed directions.
    e.point = VisiblePoint(vec3(0.0), -1.0, vec3(0.0), 0u, vec2(0.0), vec3(0.0, 0.0, 1.0),
                           vec3(0.0, 0.0, 1.0), vec3(1.0), 0u);
    e.rays = 0u;
    e.seen_by_camera = true;
    e.bounces = 0u;
    e.last_surface = false;
    return e;
}

// The ray left the scene: the world's light, or the film's transparency.
void leave_scene(inout EyePath e) {
#ifdef FILM_TRANSPARENT
    if (e.seen_by_camera) {
        e.transparent = 1.0;
        return;
    }
#ifdef FILM_TRANSPARENT_GLASS
    if (e.through_glass) {
        e.transparent = (e.throughput.r + e.throughput.g + e.throughput.b) / 3.0;
        return;
    }
#endif
#endif
    vec3 sky = environment_radiance(e.ray.dir);
    ADD_LIGHT(world, e.throughput * sky);
#ifdef DENOISING_FEATURES
    add_feature_light(e.features, sky);
#endif
}

// Surfaces the camera's rays go through: those hidden from them, and area lights (seen from
// the front unless hidden, then passed). Returns whether s was one.
bool pass_through(inout EyePath e, Surface s, bool front, int flags) {
    bool hidden = (flags & (e.seen_by_camera ? MATERIAL_HIDDEN_FROM_CAMERA
                                             : MATERIAL_HIDDEN_FROM_REFLECTIONS)) != 0;
    bool light = (flags & MATERIAL_LIGHT_SURFACE) != 0;
    if (!hidden && !light) return false;
#ifdef HAS_ABSORPTION
    // The segment just traced ran inside an absorbing object if it left through its back.
    // (Not for hidden surfaces: a ray passing an object it does not see is not inside.)
    if (light) e.throughput *= segment_transmittance(s.material, front, e.ray.origin, s.position);
#endif
    if (light && front && !hidden) {
        ADD_LIGHT(emitted, e.throughput * material_emission(s.material));
#ifdef DENOISING_FEATURES
        add_feature_light(e.features, material_emission(s.material));
#endif
    }
    e.ray = make_ray(offset_origin(s.position, s.geometric_normal, e.ray.dir), e.ray.dir);
    return true;
}

// The path holds its visible point at s: the lobes that are not followed, which the point
// stands for with the probability 1 - p_smooth of not following, and with light sampling
// the light they reflect.
void hold_visible_point(inout EyePath e, Surface s, Shading sh, vec3 wo, float p_smooth,
                        vec3 u_dir) {
    e.throughput /= 1.0 - p_smooth;
    vec3 vertex_color = vec3(1.0);
#ifdef HAS_VERTEX_COLORS
    vertex_color = s.vertex_color;
#endif
    // The true surface's normal on wo's side: the gather's side test reads it.
    uint flags = (p_smooth > 0.0 ? VISIBLE_POINT_ROUGH_ONLY : 0u) |
                 (sh.entering ? VISIBLE_POINT_ENTERING : 0u) |
                 pack_octahedral(sh.entering ? s.geometric_normal : -s.geometric_normal)
                     << VISIBLE_POINT_NORMAL_SHIFT;
    e.point = VisiblePoint(s.position, float(sh.material), e.throughput, flags, s.uv, sh.n, wo,
                           vertex_color, 0u);
#ifdef DIRECT_LIGHT_SAMPLED
    ADD_LIGHT(sampled, e.throughput * direct_light_sampled_lobes(
                           s.position, s.geometric_normal, sh, wo, p_smooth > 0.0,
                           e.light_pick, e.light_u, u_dir, e.rays));
#endif
}

// A surface the path scatters at: its emission, then a visible point or a smooth lobe
// followed. Returns whether the path goes on.
bool scatter(inout EyePath e, Surface s, bool front, int flags, inout RNG_STATE rng) {
#ifdef HAS_ABSORPTION
    e.throughput *= segment_transmittance(s.material, front, e.ray.origin, s.position);
#endif
#ifdef PASS_STRIDE
    if (!e.first_found) {
        e.first_found = true;
        e.first_depth = dot(s.position - camera_to_world[3].xyz, -camera_to_world[2].xyz);
        e.first_normal = front ? s.normal : -s.normal;
    }
#endif
    // The material as this ray sees it (mixes resolved to one leaf). Meshes emit from both
    // sides, as in Cycles, unless the material says front only (area lights, from the front).
    vec3 wo = -e.ray.dir;
    Shading sh = shading_at(s.material, s.normal, s.geometric_normal, texture_point(s),
                            s.vertex_color, wo, rng_next(rng));
    if (front || (flags & MATERIAL_ONE_SIDED_EMISSION) == 0) {
        vec3 emission = material_emission_at(s.material, sh.material, texture_point(s));
        ADD_LIGHT(emitted, e.throughput * emission);
#ifdef DENOISING_FEATURES
        add_feature_light(e.features, emission);
#endif
    }
#ifdef DENOISING_FEATURES
    if (e.features.pending)
        add_feature_surface(e.features, surface_features(s.material, sh.n, texture_point(s),
                                                         s.vertex_color, wo, sh.entering),
                            sh.n);
#endif
    if (e.last_surface) return false;
    // Smooth lobes are followed by sampling; the rest hold the visible point.
    float p_smooth = bsdf_smooth_probability(sh, wo);
    float u_lobe = rng_next(rng);
    vec3 u_dir = vec3(rng_next(rng), rng_next(rng), rng_next(rng));
    if (u_lobe >= p_smooth) {
        hold_visible_point(e, s, sh, wo, p_smooth, u_dir);
        return false;
    }
    vec3 dir, weight;
    if (!bsdf_sample_smooth(sh, wo, u_dir, dir, weight)) return false;
    e.throughput *= weight / p_smooth;
    // About a smooth shading normal the sample may cross the true surface to the other
    // side than its lobe meant: mirror it back across the surface (as photons do).
    vec3 ng_wo = sh.entering ? s.geometric_normal : -s.geometric_normal;
    float meant = dot(dir, sh.n), got = dot(dir, ng_wo);
    if (meant * got <= 0.0 && sh.kind != MATERIAL_TRANSPARENT)
        dir = normalize(dir - 2.0 * got * ng_wo);
    uint bounce = sh.kind == MATERIAL_TRANSPARENT
                      ? BOUNCE_NONE : bounce_kind(wo, dir, s.geometric_normal, false);
    e.bounces = bounces_add(e.bounces, bounce);
    e.last_surface = !bounces_within(e.bounces);
#ifdef FILM_TRANSPARENT
    e.through_glass = e.through_glass && sh.kind == MATERIAL_DIELECTRIC &&
                      dot(dir, s.geometric_normal) * dot(e.ray.dir, s.geometric_normal) > 0.0;
#endif
    e.ray = make_ray(offset_origin(s.position, s.geometric_normal, dir), dir);
    // Through a cut-out (transparent) the camera still sees what lies behind.
    if (sh.kind != MATERIAL_TRANSPARENT) e.seen_by_camera = false;
    return true;
}

// The pass's results for pixel i: its visible point, the light its path met, its passes.
void finish_pixel(uint i, EyePath e) {
    e.point.bounces = e.bounces;
    store_visible_point(i, e.point);
    vec4 sum = direct_light[2 * i + 0];
    vec4 comp = direct_light[2 * i + 1];
#ifdef FILM_TRANSPARENT
    // The transparency's sum rides in w.
    kahan_add(sum, comp, vec4(e.direct, e.transparent));
#else
    kahan_add(sum, comp, vec4(e.direct, 0.0));
#endif
    direct_light[2 * i + 0] = sum;
    direct_light[2 * i + 1] = comp;
#ifdef PASS_DEPTH
    pass_add(i, PASS_DEPTH, vec4(e.first_depth, 0.0, 0.0, 0.0));
#endif
#ifdef PASS_NORMAL
    pass_add(i, PASS_NORMAL, vec4(e.first_normal, 0.0));
#endif
#ifdef PASS_DENOISING_NORMAL
    // Cycles' camera space; 0 where the path met no surface with features.
    pass_add(i, PASS_DENOISING_NORMAL, vec4(e.features.normal, 0.0));
#endif
#ifdef PASS_DENOISING_ALBEDO
    pass_add(i, PASS_DENOISING_ALBEDO, vec4(e.features.albedo, 0.0));
#endif
#ifdef PASS_EMISSION
    pass_add(i, PASS_EMISSION, vec4(e.emitted, 0.0));
#endif
#ifdef PASS_ENVIRONMENT
    pass_add(i, PASS_ENVIRONMENT, vec4(e.world, 0.0));
#endif
#ifdef PASS_DIRECT
    pass_add(i, PASS_DIRECT, vec4(e.sampled, 0.0));
#endif
}

void main() {
    uint i = thread_index();
    if (i >= image_width * image_height) return;
#ifdef RNG_PCG
    // The pixel's stream is its index in the whole frame: a tile or render region draws the
    // numbers the whole frame's render draws there.
    RNG_STATE rng = rng_load(frame_first_pixel + (i / image_width) * frame_width + i % image_width);
#else
    RNG_STATE rng = rng_load(i);
#endif
    EyePath e = start_eye_path(i, rng);
    // At most max_bounces + 1 surfaces: max_bounces scatters, then the last surface's light.
    // Surfaces passed through (hidden, lights, cut-outs) count here too, where Cycles has a
    // separate transparent limit.
    for (uint depth = 0u; depth <= max_bounces; ++depth) {
        ++e.rays;
        Hit hit = closest_hit(e.ray);
#ifdef SPHERE_LIGHT_RECORDS
        // After a mirror or glass, a point or spot light's sphere in front of the surface.
        vec3 sphere_radiance;
        if (!e.seen_by_camera &&
            hit_sphere_light(e.ray.origin, e.ray.dir, hit.triangle < 0 ? 1e30 : hit.t,
                             sphere_radiance)) {
            ADD_LIGHT(emitted, e.throughput * sphere_radiance);
            break;
        }
#endif
        if (hit.triangle < 0) {
            leave_scene(e);
            break;
        }
        Surface s = surface_at(e.ray, hit);
        bool front = dot(e.ray.dir, s.geometric_normal) < 0.0;
        int flags = material_flags(s.material);
        if (pass_through(e, s, front, flags)) continue;
        if (!scatter(e, s, front, flags, rng)) break;
    }
    finish_pixel(i, e);
    rng_store(i, rng);
    atomicAdd(pass_rays, e.rays);
}
