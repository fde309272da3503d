// SPPM stage 1, one thread per pixel: a fresh jittered camera ray each pass, followed
// through mirrors and glass (reflection or refraction chosen by Fresnel) up to the maximum
// depth. Emission seen on the way is added to the pixel's direct light; the first
// non-specular surface becomes the pixel's visible point (Hachisuka 2015, section 2).
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
#include "common/frame.glsl"
#include "common/sppm_buffers.glsl"
#include "common/sampling.glsl"
#include "common/surface.glsl"
#include "common/bsdf.glsl"
#include "common/lobes.glsl"
#include "common/environment.glsl"
#ifdef DIRECT_LIGHT_SAMPLED
#include "common/light_sampling.glsl"
#endif

Ray camera_ray(uint x, uint y, inout RNG_STATE rng) {
    float jx = rng_next(rng), jy = rng_next(rng);
    // Film coordinates in [-1, 1], y up; row 0 is the top of the image.
    vec2 ndc = vec2(2.0 * (float(x) + jx) / float(image_width) - 1.0,
                    1.0 - 2.0 * (float(y) + jy) / float(image_height));
    vec2 film = ndc * film_half_extent + film_shift;
    vec3 origin, dir;
    if (orthographic != 0u) {
        origin = vec3(film, 0.0);
        dir = vec3(0.0, 0.0, -1.0);
    } else {
        origin = vec3(0.0);
        dir = vec3(film, -1.0);
#ifdef HAS_DEPTH_OF_FIELD
        // Thin lens: rays through the lens disc meet on the plane at the focus distance.
        vec3 focus = dir * focus_distance;
        vec2 lens = aperture_radius * sample_disc(rng_next(rng), rng_next(rng));
        origin = vec3(lens, 0.0);
        dir = focus - origin;
#endif
    }
    return make_ray((camera_to_world * vec4(origin, 1.0)).xyz,
                    normalize((camera_to_world * vec4(dir, 0.0)).xyz));
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
    vec3 normal = vec3(0.0);
    vec3 weight = vec3(0.0);
#ifdef HAS_MICROFACET
    vec4 view = vec4(0.0);
    vec2 uv = vec2(0.0);
    uint point_flags = 0u;
#endif
    uint rays = 0u;
    bool seen_by_camera = true;  // until the first specular bounce
#ifdef FILM_TRANSPARENT
    // How much of this sample leaves the scene unseen: the film's alpha is 1 - its mean.
    // The world is then not seen by such rays (Blender's Film > Transparent).
    float transparent = 0.0;
    bool through_glass = true;  // every bounce so far a transmission through glass
#endif
    for (uint depth = 0u; depth < max_depth; ++depth) {
        ++rays;
        Hit hit = closest_hit(ray);
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
            direct += throughput * environment_radiance(ray.dir);
            break;
        }
        Surface s = surface_at(ray, hit);
        bool front = dot(ray.dir, s.geometric_normal) < 0.0;
        int flags = material_flags(s.material);
        bool hidden = seen_by_camera && (flags & MATERIAL_HIDDEN_FROM_CAMERA) != 0;
        if (hidden && (flags & MATERIAL_LIGHT_SURFACE) == 0) {
            // Not visible to the camera: camera rays go on as if it were not there.
            ray = make_ray(offset_origin(s.position, s.geometric_normal, ray.dir), ray.dir);
            continue;
        }
        if ((flags & MATERIAL_LIGHT_SURFACE) != 0) {
            // An area light: seen (unless hidden from the camera), then passed through.
            if (front && !hidden) direct += throughput * material_emission(s.material);
            ray = make_ray(offset_origin(s.position, s.geometric_normal, ray.dir), ray.dir);
            continue;
        }
#ifdef HAS_MICROFACET
        // The material as this ray sees it (mixes resolved to one leaf).
        vec3 wo = -ray.dir;
        Shading sh = shading_at(s.material, s.normal, s.geometric_normal, s.uv, wo, rng_next(rng));
        if (front || (flags & MATERIAL_ONE_SIDED_EMISSION) == 0)
            direct += throughput * material_emission_at(s.material, sh.material, s.uv);
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
            weight = throughput;
            point_flags = (p_smooth > 0.0 ? VISIBLE_POINT_ROUGH_ONLY : 0u) |
                          (sh.entering ? VISIBLE_POINT_ENTERING : 0u);
#ifdef HAS_NORMAL_MAP
            point_flags |= pack_octahedral(sh.ng) << VISIBLE_POINT_NORMAL_SHIFT;
#endif
#ifdef DIRECT_LIGHT_SAMPLED
            direct += throughput * direct_light_sampled_lobes(s.position, s.geometric_normal, sh,
                                                              wo, p_smooth > 0.0, light_pick,
                                                              light_u, u_dir, rays);
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
#else
        // Meshes emit from both sides, as in Cycles, unless the material says front only
        // (area lights, above, from the front).
        if (front || (flags & MATERIAL_ONE_SIDED_EMISSION) == 0)
            direct += throughput * material_emission_at(s.material, s.material, s.uv);
        int kind = material_kind(s.material);
        vec3 color = surface_color(s);
        if (kind == MATERIAL_DIFFUSE) {
            point = vec4(s.position, float(s.material));
            normal = front ? s.normal : -s.normal;
            weight = throughput * color / PI;
#ifdef DIRECT_LIGHT_SAMPLED
            // Direct light by one light sample; photons bring only the rest. The eye path
            // ends here, so no BSDF-sampled ray can also reach a light from this point and
            // light sampling needs no MIS weight: emission seen directly or through specular
            // chains (above) is the only other way eye paths meet lights, as before.
            direct += throughput * direct_light_sampled(s.position, normal,
                                                        front ? s.geometric_normal
                                                              : -s.geometric_normal,
                                                        -ray.dir, s.material, color,
                                                        light_pick, light_u, rays);
#endif
            break;
        }
        vec3 dir = scatter_specular(s.material, color, ray.dir, s.normal, s.geometric_normal,
                                    rng_next(rng), true, throughput);
#endif
#ifdef FILM_TRANSPARENT
        through_glass = through_glass && kind == MATERIAL_DIELECTRIC &&
                        dot(dir, s.geometric_normal) * dot(ray.dir, s.geometric_normal) > 0.0;
#endif
        ray = make_ray(offset_origin(s.position, s.geometric_normal, dir), dir);
#ifdef HAS_MICROFACET
        // Through a cut-out (transparent) the camera still sees what lies behind.
        if (kind == MATERIAL_TRANSPARENT) continue;
#endif
        seen_by_camera = false;
    }

#ifdef HAS_MICROFACET
    visible_points[4 * i + 0] = point;
    visible_points[4 * i + 1] = vec4(normal, uv.x);
    visible_points[4 * i + 2] = vec4(view.xyz, uv.y);
    visible_points[4 * i + 3] = vec4(weight, uintBitsToFloat(point_flags));
#else
    visible_points[3 * i + 0] = point;
    visible_points[3 * i + 1] = vec4(normal, 0.0);
    visible_points[3 * i + 2] = vec4(weight, 0.0);
#endif
    // Kahan summation: after 1e5 passes a plain float sum stops absorbing increments.
    vec4 sum = direct_light[2 * i + 0];
    vec4 comp = direct_light[2 * i + 1];
    precise vec3 y = direct - comp.xyz;
    precise vec3 t = sum.xyz + y;
    precise vec3 c = (t - sum.xyz) - y;
    comp.xyz = c;
#ifdef FILM_TRANSPARENT
    // The transparency's sum rides in w, compensated the same way.
    precise float ya = transparent - comp.w;
    precise float ta = sum.w + ya;
    comp.w = (ta - sum.w) - ya;
    direct_light[2 * i + 0] = vec4(t, ta);
#else
    direct_light[2 * i + 0] = vec4(t, 0.0);
#endif
    direct_light[2 * i + 1] = comp;
    rng_store(i, rng);
    atomicAdd(pass_rays, rays);
}
