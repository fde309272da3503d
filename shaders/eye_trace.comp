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
#include "common/light_groups.glsl"
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

// Light on the eye path goes into Combined's sum and, with render passes, into its part of
// the light split as well: emission, the world, or light sampled at the visible point; with
// light groups into its emitter's group too (common/light_groups.glsl; `group` is a code).
#ifdef LIGHT_GROUPS
#define ADD_LIGHT(part, group, value)                                  \
    { vec3 light_ = (value); direct += light_; part += light_;         \
      light_group_add(group, light_, throughput); }
#elif defined(PASS_STRIDE)
#define ADD_LIGHT(part, group, value) { vec3 light_ = (value); direct += light_; part += light_; }
#else
#define ADD_LIGHT(part, group, value) direct += (value)
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
#ifdef DIRECT_LIGHT_SAMPLED
    // The light sample's numbers come first, so that draws only some variants make (the
    // lens) do not change them: every variant of a scene renders the same image.
    float light_pick = rng_next(rng);
    vec4 light_u = vec4(rng_next(rng), rng_next(rng), rng_next(rng), rng_next(rng));
#endif
    Ray ray = camera_ray(i % image_width, i / image_width, rng);

    vec3 throughput = vec3(1.0);
    vec3 direct = vec3(0.0);
    vec4 point = vec4(0.0, 0.0, 0.0, -1.0);  // w: material id, -1 = none
    vec3 normal = vec3(0.0, 0.0, 1.0);  // any unit vector where there is no point
    vec3 weight = vec3(0.0);
    vec4 view = vec4(0.0, 0.0, 1.0, 0.0);
    vec2 uv = vec2(0.0);
    uint point_flags = 0u;
#ifdef HAS_VERTEX_COLORS
    vec3 vertex_color = vec3(1.0);
#endif
    uint rays = 0u;
    bool seen_by_camera = true;  // until the first specular bounce
    // The eye subpath's scatters so far (common/bounces.glsl). One past a limit, the path
    // still takes the emission (and the world) of the surface it meets next, as Cycles'
    // PATH_RAY_TERMINATE_AFTER_TRANSPARENT, and ends there: no visible point, no light sample.
    uint eye_bounces = 0u;
    bool last_surface = false;
#ifdef PASS_STRIDE
    vec3 emitted = vec3(0.0), world = vec3(0.0), sampled = vec3(0.0);
    // The first surface the camera sees (Depth, Normal): Cycles' z-depth along the view axis,
    // 1e10 where the ray leaves the scene, and the normal facing the camera.
    float first_depth = 1e10;
    vec3 first_normal = vec3(0.0);
    bool first_found = false;
#endif
#ifdef DENOISING_FEATURES
    DenoisingFeatures features = start_denoising_features();
#endif
#ifdef LIGHT_GROUPS
    light_groups_begin();
#endif
#ifdef FILM_TRANSPARENT
    // How much of this sample leaves the scene unseen: the film's alpha is 1 - its mean.
    // The world is then not seen by such rays (Blender's Film > Transparent).
    float transparent = 0.0;
    bool through_glass = true;  // every bounce so far a transmission through glass
#endif
    // At most max_bounces + 1 surfaces: max_bounces scatters, then the last surface's light.
    // Surfaces passed through (hidden, lights, cut-outs) count here too, where Cycles has a
    // separate transparent limit.
    for (uint depth = 0u; depth <= max_bounces; ++depth) {
        ++rays;
        Hit hit = closest_hit(ray);
#ifdef SPHERE_LIGHT_RECORDS
        // After a mirror or glass, a point or spot light's sphere in front of the surface.
        vec3 sphere_radiance;
        if (!seen_by_camera &&
            hit_sphere_light(ray.origin, ray.dir, hit.triangle < 0 ? 1e30 : hit.t,
                             sphere_radiance)) {
            ADD_LIGHT(emitted, sphere_light_group_code, throughput * sphere_radiance);
            break;
        }
#endif
        if (hit.triangle < 0) {
#ifdef FILM_TRANSPARENT
            if (seen_by_camera) {
                transparent = 1.0;
                break;
            }
#ifdef FILM_TRANSPARENT_GLASS
            if (through_glass) {
                transparent = (throughput.r + throughput.g + throughput.b) / 3.0;
                break;
            }
#endif
#endif
            vec3 sky = environment_radiance(ray.dir);
            ADD_LIGHT(world, WORLD_GROUP_CODE, throughput * sky);
#ifdef DENOISING_FEATURES
            add_feature_light(features, sky);
#endif
            break;
        }
        Surface s = surface_at(ray, hit);
        bool front = dot(ray.dir, s.geometric_normal) < 0.0;
        int flags = material_flags(s.material);
        bool hidden = (flags & (seen_by_camera ? MATERIAL_HIDDEN_FROM_CAMERA
                                               : MATERIAL_HIDDEN_FROM_REFLECTIONS)) != 0;
        if (hidden && (flags & MATERIAL_LIGHT_SURFACE) == 0) {
            // Not visible to the camera: camera rays go on as if it were not there.
            ray = make_ray(offset_origin(s.position, s.geometric_normal, ray.dir), ray.dir);
            continue;
        }
#ifdef HAS_ABSORPTION
        // The segment just traced ran inside an absorbing object if it left through its back.
        // (After the hidden surfaces: a ray passing an object it does not see is not inside.)
        throughput *= segment_transmittance(s.material, front, ray.origin, s.position);
#endif
        if ((flags & MATERIAL_LIGHT_SURFACE) != 0) {
            // An area light: seen (unless hidden from the camera), then passed through.
            if (front && !hidden) {
                ADD_LIGHT(emitted, material_group_code(s.material),
                          throughput * material_emission(s.material));
#ifdef DENOISING_FEATURES
                add_feature_light(features, material_emission(s.material));
#endif
            }
            ray = make_ray(offset_origin(s.position, s.geometric_normal, ray.dir), ray.dir);
            continue;
        }
#ifdef PASS_STRIDE
        if (!first_found) {
            first_found = true;
            first_depth = dot(s.position - camera_to_world[3].xyz, -camera_to_world[2].xyz);
            first_normal = front ? s.normal : -s.normal;
        }
#endif
        // The material as this ray sees it (mixes resolved to one leaf). Meshes emit from both
        // sides, as in Cycles, unless the material says front only (area lights, above, from
        // the front).
        vec3 wo = -ray.dir;
        Shading sh = shading_at(s.material, s.normal, s.geometric_normal, texture_point(s),
                                s.vertex_color, wo, rng_next(rng));
        if (front || (flags & MATERIAL_ONE_SIDED_EMISSION) == 0) {
            vec3 emission = material_emission_at(s.material, sh.material, texture_point(s));
            ADD_LIGHT(emitted, material_group_code(s.material), throughput * emission);
#ifdef DENOISING_FEATURES
            add_feature_light(features, emission);
#endif
        }
#ifdef DENOISING_FEATURES
        if (features.pending)
            add_feature_surface(features, surface_features(s.material, sh.n, texture_point(s),
                                                           s.vertex_color, wo, sh.entering),
                                sh.n);
#endif
        if (last_surface) break;
        // Smooth lobes are followed by sampling; the rest hold the visible point, which
        // stands for them with the probability of not following.
        float p_smooth = bsdf_smooth_probability(sh, wo);
        float u_lobe = rng_next(rng);
        vec3 u_dir = vec3(rng_next(rng), rng_next(rng), rng_next(rng));
        if (u_lobe >= p_smooth) {
            throughput /= 1.0 - p_smooth;
            point = vec4(s.position, float(sh.material));
            normal = sh.n;
            view = vec4(wo, 0.0);
            uv = s.uv;
#ifdef HAS_VERTEX_COLORS
            vertex_color = s.vertex_color;
#endif
            weight = throughput;
            // The true surface's normal on wo's side: the gather's side test reads it.
            point_flags = (p_smooth > 0.0 ? VISIBLE_POINT_ROUGH_ONLY : 0u) |
                          (sh.entering ? VISIBLE_POINT_ENTERING : 0u) |
                          pack_octahedral(sh.entering ? s.geometric_normal : -s.geometric_normal)
                              << VISIBLE_POINT_NORMAL_SHIFT;
#ifdef DIRECT_LIGHT_SAMPLED
            ADD_LIGHT(sampled, LIGHT_GROUP_SAMPLED, throughput * direct_light_sampled_lobes(
                                   s.position, s.geometric_normal, sh, wo, p_smooth > 0.0,
                                   light_pick, light_u, u_dir, rays));
#endif
            break;
        }
        vec3 dir, sampled;
        if (!bsdf_sample_smooth(sh, wo, u_dir, dir, sampled)) break;
        throughput *= sampled / p_smooth;
        // About a smooth shading normal the sample may cross the true surface to the other
        // side than its lobe meant: mirror it back across the surface (as photons do).
        vec3 ng_wo = sh.entering ? s.geometric_normal : -s.geometric_normal;
        float meant = dot(dir, sh.n), got = dot(dir, ng_wo);
        if (meant * got <= 0.0 && sh.kind != MATERIAL_TRANSPARENT)
            dir = normalize(dir - 2.0 * got * ng_wo);
        int kind = sh.kind;
        uint bounce = kind == MATERIAL_TRANSPARENT
                          ? BOUNCE_NONE : bounce_kind(wo, dir, s.geometric_normal, false);
        eye_bounces = bounces_add(eye_bounces, bounce);
        last_surface = !bounces_within(eye_bounces);
#ifdef FILM_TRANSPARENT
        through_glass = through_glass && kind == MATERIAL_DIELECTRIC &&
                        dot(dir, s.geometric_normal) * dot(ray.dir, s.geometric_normal) > 0.0;
#endif
        ray = make_ray(offset_origin(s.position, s.geometric_normal, dir), dir);
        // Through a cut-out (transparent) the camera still sees what lies behind.
        if (kind == MATERIAL_TRANSPARENT) continue;
        seen_by_camera = false;
    }

#ifndef HAS_VERTEX_COLORS
    vec3 vertex_color = vec3(1.0);
#endif
    store_visible_point(i, VisiblePoint(point.xyz, point.w, weight, point_flags, uv, normal,
                                        view.xyz, vertex_color, eye_bounces));
    vec4 sum = direct_light[2 * i + 0];
    vec4 comp = direct_light[2 * i + 1];
#ifdef FILM_TRANSPARENT
    // The transparency's sum rides in w.
    kahan_add(sum, comp, vec4(direct, transparent));
#else
    kahan_add(sum, comp, vec4(direct, 0.0));
#endif
    direct_light[2 * i + 0] = sum;
    direct_light[2 * i + 1] = comp;
#ifdef PASS_DEPTH
    pass_add(i, PASS_DEPTH, vec4(first_depth, 0.0, 0.0, 0.0));
#endif
#ifdef PASS_NORMAL
    pass_add(i, PASS_NORMAL, vec4(first_normal, 0.0));
#endif
#ifdef PASS_DENOISING_NORMAL
    // Cycles' camera space; 0 where the path met no surface with features.
    pass_add(i, PASS_DENOISING_NORMAL, vec4(features.normal, 0.0));
#endif
#ifdef PASS_DENOISING_ALBEDO
    pass_add(i, PASS_DENOISING_ALBEDO, vec4(features.albedo, 0.0));
#endif
#ifdef PASS_EMISSION
    pass_add(i, PASS_EMISSION, vec4(emitted, 0.0));
#endif
#ifdef PASS_ENVIRONMENT
    pass_add(i, PASS_ENVIRONMENT, vec4(world, 0.0));
#endif
#ifdef PASS_DIRECT
    pass_add(i, PASS_DIRECT, vec4(sampled, 0.0));
#endif
#ifdef LIGHT_GROUPS
    store_light_groups(i);
#endif
    rng_store(i, rng);
    atomicAdd(pass_rays, rays);
}
