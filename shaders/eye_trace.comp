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
#include "common/light_linking.glsl"
#ifdef VCM_MIS
#include "common/bounces.glsl"
#include "common/light_tracing.glsl"
#include "common/vcm_mis.glsl"
#include "common/vcm_merging.glsl"
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

// Light on the eye path goes into Combined's sum and, with render passes, into its part of
// the light split as well: emission, the world, or light sampled at the visible point; with
// light groups into its emitter's group too (common/light_groups.glsl; `group` is a code).
// The light sample's parts go into their groups inside direct_light_sampled_lobes, times
// the throughput, which is set before `value` is computed.
#ifdef LIGHT_GROUPS
#define ADD_LIGHT(part, group, value)              \
    {                                              \
        light_group_throughput = throughput;       \
        vec3 light_ = (value);                     \
        direct += light_;                          \
        passes.part += light_;                     \
        light_group_add(group, light_);             \
    }
#elif defined(PASS_STRIDE)
#define ADD_LIGHT(part, group, value) { vec3 light_ = (value); direct += light_; passes.part += light_; }
#else
#define ADD_LIGHT(part, group, value) direct += (value)
#endif
// Light the path sees on a surface or the world: Combined, its part, and the denoising
// albedo's light.
#ifdef DENOISING_FEATURES
#define SEE_LIGHT(part, group, radiance)            \
    {                                               \
        vec3 seen_ = (radiance);                    \
        ADD_LIGHT(part, group, throughput * seen_); \
        add_feature_light(features, seen_);         \
    }
#else
#define SEE_LIGHT(part, group, radiance) ADD_LIGHT(part, group, throughput * (radiance))
#endif
// Light linking (common/light_linking.glsl): emission of link set `set` met after a mirror or
// glass counts where it reaches the surface the path last scattered from (eye_link_receiver,
// which SET_EYE_LINK_RECEIVER sets); the camera's own view is not linked, as in Cycles.
#ifdef LIGHT_LINKING
#define EYE_LINK_REACHES(set) eye_link_reaches(set)
#define SET_EYE_LINK_RECEIVER(m) eye_link_receiver = (m)
#else
#define EYE_LINK_REACHES(set) true
#define SET_EYE_LINK_RECEIVER(m)
#endif
// Emission of material m (its group's and link set's) and the world (link set 0) the path sees.
#define SEE_EMISSION(m, radiance)               \
    if (EYE_LINK_REACHES(material_link_set(m))) \
        SEE_LIGHT(emitted, material_group_code(m), radiance)
#define SEE_WORLD(dir)    \
    if (EYE_LINK_REACHES(0u)) \
        SEE_LIGHT(world, WORLD_GROUP_CODE, environment_radiance(dir) * WORLD_MIS(dir))

// Light samples at followed glossy vertices (common/glossy_light_samples.glsl), their numbers
// drawn only there. The emission the continuation meets weighs against them: an emissive
// triangle main's ray hit (HIT_MIS), the sphere light it met (SPHERE_MIS), the world. Where
// an emitter kind has no record (no HAS_EMITTER_MIS, no world) the weight is 1, written so:
// NVIDIA's compiler rejects even an unreachable emitter record at a constant index of -1.
#ifdef GLOSSY_LIGHT_SAMPLES
// LIGHT_VERTEX(hold): where the vertex takes a light sample, `hold` telling whether it holds
// the visible point. Without glossy light samples it is the visible point's branch exactly as
// it was (hold is true in it): a shared branch cost those scenes 9% on an H100.
#define LIGHT_VERTEX(hold)          \
    bool hold = u_lobe >= p_smooth; \
    if (hold || ((depth < max_bounces) && glossy_followed_lobe(sh)))
#define GLOSSY_LIGHT_NUMBERS(hold) \
    if (!(hold)) light_numbers = draw_light_sample_numbers(rng)
#define FOLLOWED(hold) ((hold) ? 0.0 : p_smooth)
#define GLOSSY_MIS_LEAVE() \
    glossy_mis_leave(sh, wo, dir, p_smooth, s.position, glossy_followed_lobe(sh))
#define SPHERE_MIS glossy_emission_weight(int(sphere_light_record), ray.dir, ray.origin)
#ifdef HAS_EMITTER_MIS
#define HIT_MIS glossy_emission_weight(triangle_emitter(hit.triangle), ray.dir, s.position)
#else
#define HIT_MIS 1.0
#endif
#ifdef HAS_ENVIRONMENT
#define WORLD_MIS(dir) glossy_emission_weight(world_emitter(), dir, ray.origin)
#else
#define WORLD_MIS(dir) 1.0
#endif
#else
#define LIGHT_VERTEX(hold) \
    const bool hold = true;  \
    if (u_lobe >= p_smooth)
#define GLOSSY_LIGHT_NUMBERS(hold)
#define FOLLOWED(hold) 0.0
#define GLOSSY_MIS_LEAVE()
#define SPHERE_MIS 1.0
#define HIT_MIS 1.0
#define WORLD_MIS(dir) 1.0
#endif

// The numbers of the pixel's light sample, drawn first, so that draws only some variants
// make (the lens) do not change them: every variant of a scene renders the same image.
struct LightSampleNumbers {
    float pick;
    vec4 u;
};

LightSampleNumbers draw_light_sample_numbers(inout RNG_STATE rng) {
    float pick = rng_next(rng);
    return LightSampleNumbers(pick, vec4(rng_next(rng), rng_next(rng), rng_next(rng),
                                         rng_next(rng)));
}

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

// Pixel i's index in the whole frame: a tile or render region draws the numbers the whole
// frame's render draws there.
uint frame_pixel_index(uint i) {
    return frame_first_pixel + (i / image_width) * frame_width + i % image_width;
}

RNG_STATE load_pixel_rng(uint i) {
#ifdef RNG_PCG
    // The pixel's stream is its index in the whole frame.
    return rng_load(frame_pixel_index(i));
#else
    return rng_load(i);
#endif
}

#ifdef PASS_STRIDE
// The render passes' share of the eye path besides Combined: its light split (emission,
// the world, light sampled at the visible point) and the first surface the camera sees
// (Depth, Normal): Cycles' z-depth along the view axis, 1e10 where the ray leaves the scene,
// and the normal facing the camera.
struct EyePasses {
    vec3 emitted, world, sampled;
    float first_depth;
    vec3 first_normal;
    bool first_found;
};

// Light groups (common/light_groups.glsl) are render passes too: their sums start and are
// stored with the others'.
EyePasses start_eye_passes() {
#ifdef LIGHT_GROUPS
    light_groups_begin();
#endif
    return EyePasses(vec3(0.0), vec3(0.0), vec3(0.0), 1e10, vec3(0.0), false);
}

void note_first_surface(inout EyePasses passes, Surface s, bool front) {
    if (passes.first_found) return;
    passes.first_found = true;
    passes.first_depth = dot(s.position - camera_to_world[3].xyz, -camera_to_world[2].xyz);
    passes.first_normal = front ? s.normal : -s.normal;
}

void store_eye_passes(uint i, EyePasses passes) {
#ifdef PASS_DEPTH
    pass_add(i, PASS_DEPTH, vec4(passes.first_depth, 0.0, 0.0, 0.0));
#endif
#ifdef PASS_NORMAL
    pass_add(i, PASS_NORMAL, vec4(passes.first_normal, 0.0));
#endif
#ifdef PASS_EMISSION
    pass_add(i, PASS_EMISSION, vec4(passes.emitted, 0.0));
#endif
#ifdef PASS_ENVIRONMENT
    pass_add(i, PASS_ENVIRONMENT, vec4(passes.world, 0.0));
#endif
#ifdef PASS_DIRECT
    pass_add(i, PASS_DIRECT, vec4(passes.sampled, 0.0));
#endif
#ifdef LIGHT_GROUPS
    store_light_groups(i);
#endif
}
#endif

#ifdef DENOISING_FEATURES
void store_denoising_passes(uint i, DenoisingFeatures features) {
#ifdef PASS_DENOISING_NORMAL
    // Cycles' camera space; 0 where the path met no surface with features.
    pass_add(i, PASS_DENOISING_NORMAL, vec4(features.normal, 0.0));
#endif
#ifdef PASS_DENOISING_ALBEDO
    pass_add(i, PASS_DENOISING_ALBEDO, vec4(features.albedo, 0.0));
#endif
}
#endif

#ifdef FILM_TRANSPARENT
// Whether a ray that left the scene is transparent film rather than the world: seen by the
// camera directly, or (FILM_TRANSPARENT_GLASS) through glass alone. `transparent` is how
// much of the sample the film's alpha leaves out (Blender's Film > Transparent).
bool leaves_through_film(bool seen_by_camera, bool through_glass, vec3 throughput,
                         inout float transparent) {
    if (seen_by_camera) {
        transparent = 1.0;
        return true;
    }
#ifdef FILM_TRANSPARENT_GLASS
    if (through_glass) {
        transparent = (throughput.r + throughput.g + throughput.b) / 3.0;
        return true;
    }
#endif
    return false;
}
#endif

// The pixel's visible point at s: the lobes the path did not follow, standing for them with
// the eye path's weight. The flag word holds the true surface's normal on wo's side, which
// the gather's side test reads.
void hold_visible_point(uint i, Surface s, Shading sh, vec3 wo, vec3 weight, bool rough_only,
                        uint eye_bounces) {
    uint flags = (rough_only ? VISIBLE_POINT_ROUGH_ONLY : 0u) |
                 (sh.entering ? VISIBLE_POINT_ENTERING : 0u) |
                 pack_octahedral(sh.entering ? s.geometric_normal : -s.geometric_normal)
                     << VISIBLE_POINT_NORMAL_SHIFT;
#ifdef HAS_VERTEX_COLORS
    vec3 vertex_color = s.vertex_color;
#else
    vec3 vertex_color = vec3(1.0);
#endif
    store_visible_point(i, VisiblePoint(s.position, float(sh.material), weight, flags, s.uv,
                                        sh.n, wo, vertex_color, eye_bounces));
}

#ifdef SPHERE_LIGHT_RECORDS
// Whether the ray meets a point or spot light's sphere before the surface it hits (if any).
bool sphere_light_before_hit(Ray ray, Hit hit, out vec3 radiance) {
    return hit_sphere_light(ray.origin, ray.dir, hit.triangle < 0 ? 1e30 : hit.t, radiance);
}
#endif

#ifdef LIGHT_LINKING
// Shadow linking of the emission an eye path meets past a mirror or glass, as Cycles does it
// (its dedicated light: intersect_dedicated_light.h): where the surface `s` the path is about
// to scatter at does not shadow every link set, the emitters behind it whose sets nothing on
// the way shadows still light the path. The ray goes on past `s` and the surfaces after it,
// keeping the sets each shadows (the row's mask; area lights and surfaces hidden from
// reflections are passed, as the eye path passes them), until every set is shadowed; of the
// emitters it meets whose light reaches the path's receiver and whose set is not shadowed one
// is picked, uniformly, and its radiance (with its MIS weight, as main's) returned times
// their count, with its group code. An ordinary surface shadows every set: nothing is traced.
const int EYE_LINK_CROSSINGS = 8;
#ifdef LIGHT_GROUPS
#define EYE_LINK_GROUP(code) code
#else
#define EYE_LINK_GROUP(code) 0u
#endif

vec3 eye_light_past_blockers(Ray path_ray, Surface past, inout RNG_STATE rng, inout uint rays,
                             out uint group) {
    group = 0u;
    vec3 picked = vec3(0.0);
    float count = 0.0;
    uint shadowed = shadow_link_blocks[material_link_row(past.material)];
    Ray ray = make_ray(offset_origin(past.position, past.geometric_normal, path_ray.dir),
                       path_ray.dir);
    for (int crossing = 0; crossing < EYE_LINK_CROSSINGS && shadowed != 0xFFFFFFFFu;
         ++crossing) {
        ++rays;
        Hit hit = closest_hit(ray);
        vec3 radiance = vec3(0.0);
        uint code = 0u, set = 0u, shadowed_before = shadowed;
        bool last = true;
#ifdef SPHERE_LIGHT_RECORDS
        if (sphere_light_before_hit(ray, hit, radiance)) {  // reaches the receiver (its check)
            set = emitter_link_set(sphere_light_record);
            code = EYE_LINK_GROUP(emitter_group_code(sphere_light_record));
            radiance *= SPHERE_MIS;
        } else
#endif
        if (hit.triangle < 0) {
            if (EYE_LINK_REACHES(0u)) radiance = environment_radiance(ray.dir) * WORLD_MIS(ray.dir);
            code = EYE_LINK_GROUP(WORLD_GROUP_CODE);
        } else {
            Surface s = surface_at(ray, hit);
            int flags = material_flags(s.material);
            bool front = dot(ray.dir, s.geometric_normal) < 0.0;
            set = material_link_set(s.material);
            code = EYE_LINK_GROUP(material_group_code(s.material));
            last = false;
            if ((flags & MATERIAL_HIDDEN_FROM_REFLECTIONS) != 0) {
            } else if ((flags & MATERIAL_LIGHT_SURFACE) != 0) {
                if (front) radiance = material_emission(s.material) * HIT_MIS;
            } else {
                if (front || (flags & MATERIAL_ONE_SIDED_EMISSION) == 0) {
                    Shading sh = shading_at(s.material, s.normal, s.geometric_normal,
                                            texture_point(s), s.vertex_color, -ray.dir,
                                            rng_next(rng));
                    radiance = material_emission_at(s.material, sh.material, texture_point(s)) *
                               HIT_MIS;
                }
                shadowed |= shadow_link_blocks[material_link_row(s.material)];
            }
            if (!EYE_LINK_REACHES(set)) radiance = vec3(0.0);
            ray = make_ray(offset_origin(s.position, s.geometric_normal, ray.dir), ray.dir);
        }
        if (any(greaterThan(radiance, vec3(0.0))) && ((shadowed_before >> set) & 1u) == 0u) {
            count += 1.0;
            if (rng_next(rng) * count < 1.0) {
                picked = radiance;
                group = code;
            }
        }
        if (last) break;
    }
    return picked * count;
}
#define EYE_LIGHT_PAST_BLOCKERS(s)                                                 \
    if (!seen_by_camera) {                                                         \
        uint group_;                                                               \
        vec3 past_ = eye_light_past_blockers(ray, s, rng, rays, group_);           \
        if (any(greaterThan(past_, vec3(0.0)))) SEE_LIGHT(emitted, group_, past_); \
    }
#else
#define EYE_LIGHT_PAST_BLOCKERS(s)
#endif

// The bounce word's kind of a smooth lobe's sample: a cut-out's is no scatter.
uint smooth_bounce_kind(Shading sh, vec3 wo, vec3 wi, vec3 ng) {
    return sh.kind == MATERIAL_TRANSPARENT ? BOUNCE_NONE : bounce_kind(wo, wi, ng, false);
}

#ifdef DENOISING_FEATURES
// The denoising features of the surface the path meets, while they are still pending.
void add_feature_surface_at(inout DenoisingFeatures features, Surface s, Shading sh, vec3 wo) {
    if (features.pending)
        add_feature_surface(features, surface_features(s.material, sh.n, texture_point(s),
                                                       s.vertex_color, wo, sh.entering),
                            sh.n);
}
#endif

// A pixel whose path ended without a visible point (material -1: the gather skips it).
void hold_no_visible_point(uint i, uint eye_bounces) {
    store_visible_point(i, VisiblePoint(vec3(0.0), -1.0, vec3(0.0), 0u, vec2(0.0),
                                        vec3(0.0, 0.0, 1.0), vec3(0.0, 0.0, 1.0), vec3(1.0),
                                        eye_bounces));
}

// The light the pass's path saw (and, with a transparent film, its transparency in w),
// added to the pixel's compensated sum.
void add_direct_light(uint i, vec4 light) {
    vec4 sum = direct_light[2 * i + 0];
    vec4 comp = direct_light[2 * i + 1];
    kahan_add(sum, comp, light);
    direct_light[2 * i + 0] = sum;
    direct_light[2 * i + 1] = comp;
}

#ifdef ESTIMATOR_VCM
// VCM's eye subpaths (docs/vcm.md) in place of the visible points' main below.
#include "common/vcm_eye_paths.glsl"
#else
// The eye path: at most max_bounces + 1 surfaces, max_bounces scatters and then the last
// surface's light. Surfaces passed through (hidden, lights, cut-outs) count here too, where
// Cycles has a separate transparent limit. `eye_bounces` counts the scatters
// (common/bounces.glsl); one past a limit, the path still takes the emission (and the
// world) of the surface it meets next, as Cycles' PATH_RAY_TERMINATE_AFTER_TRANSPARENT, and
// ends there: no visible point, no light sample. Its state stays in main's locals: passed
// around as a struct through inout functions it made the eye stage 1.5x slower on the H200.
// Whether this pass's Lambertian points of pixel i's work group take the BSDF sample of
// their direct light (issue 30, common/light_sampling.glsl).
#ifdef HAS_EMITTER_MIS
#define EMITTER_MIS_CHOICE(i) emitter_mis_choice(frame_pixel_index(i))
#else
#define EMITTER_MIS_CHOICE(i)
#endif

// `held`: whether the path holds a visible point; `seen_by_camera`: it has met no specular
// bounce yet; `last_surface`: it is past a limit. The light sample of the visible point or of
// a followed glossy vertex (with numbers of its own) is one call: one copy of its code in the
// loop (two made the glossy Cornell box's passes 1.9x slower on an H100).
void main() {
    uint i = thread_index();
    if (i >= image_width * image_height) return;
    RNG_STATE rng = load_pixel_rng(i);
#ifdef DIRECT_LIGHT_SAMPLED
    LightSampleNumbers light_numbers = draw_light_sample_numbers(rng);
#endif
    EMITTER_MIS_CHOICE(i);
    Ray ray = camera_ray(i % image_width, i / image_width, rng);
    vec3 throughput = vec3(1.0), direct = vec3(0.0);
    uint rays = 0u, eye_bounces = 0u;
    bool held = false, seen_by_camera = true, last_surface = false;
#ifdef PASS_STRIDE
    EyePasses passes = start_eye_passes();
#endif
#ifdef DENOISING_FEATURES
    DenoisingFeatures features = start_denoising_features();
#endif
    float transparent = 0.0;  // the film's transparency (FILM_TRANSPARENT)
    bool through_glass = true;  // every bounce so far a transmission through glass
    for (uint depth = 0u; depth <= max_bounces; ++depth) {
        ++rays;
        Hit hit = closest_hit(ray);
#ifdef SPHERE_LIGHT_RECORDS
        vec3 sphere_radiance;  // after a mirror or glass, a sphere light before the surface
        if (!seen_by_camera && sphere_light_before_hit(ray, hit, sphere_radiance)) {
            ADD_LIGHT(emitted, sphere_light_group_code, throughput * sphere_radiance * SPHERE_MIS);
            break;
        }
#endif
        if (hit.triangle < 0) {
#ifdef FILM_TRANSPARENT
            if (leaves_through_film(seen_by_camera, through_glass, throughput, transparent))
                break;
#endif
            SEE_WORLD(ray.dir);
            break;
        }
        Surface s = surface_at(ray, hit);
        bool front = dot(ray.dir, s.geometric_normal) < 0.0;
        int flags = material_flags(s.material);
        bool hidden = (flags & (seen_by_camera ? MATERIAL_HIDDEN_FROM_CAMERA
                                               : MATERIAL_HIDDEN_FROM_REFLECTIONS)) != 0;
        if (hidden && (flags & MATERIAL_LIGHT_SURFACE) == 0) {  // rays go on past it
            ray = make_ray(offset_origin(s.position, s.geometric_normal, ray.dir), ray.dir);
            continue;
        }
#ifdef HAS_ABSORPTION
        // Inside an absorbing object if the ray left through its back (not a hidden one's).
        throughput *= segment_transmittance(s.material, front, ray.origin, s.position);
#endif
        if ((flags & MATERIAL_LIGHT_SURFACE) != 0) {
            // An area light: seen (unless hidden from the camera), then passed through.
            if (front && !hidden) SEE_EMISSION(s.material, material_emission(s.material) * HIT_MIS);
            ray = make_ray(offset_origin(s.position, s.geometric_normal, ray.dir), ray.dir);
            continue;
        }
        EYE_LIGHT_PAST_BLOCKERS(s);
#ifdef PASS_STRIDE
        note_first_surface(passes, s, front);
#endif
        // The material as this ray sees it (mixes resolved to one leaf); smooth lobes are
        // followed, the rest hold the visible point. Meshes emit from both sides, as in
        // Cycles, unless the material says front only.
        vec3 wo = -ray.dir;
        Shading sh = shading_at(s.material, s.normal, s.geometric_normal, texture_point(s),
                                s.vertex_color, wo, rng_next(rng));
        if (front || (flags & MATERIAL_ONE_SIDED_EMISSION) == 0)
            SEE_EMISSION(s.material, material_emission_at(s.material, sh.material,
                                                          texture_point(s)) * HIT_MIS);
#ifdef DENOISING_FEATURES
        add_feature_surface_at(features, s, sh, wo);
#endif
        if (last_surface) break;
        float p_smooth = bsdf_smooth_probability(sh, wo);
        float u_lobe = rng_next(rng);
        vec3 u_dir = vec3(rng_next(rng), rng_next(rng), rng_next(rng));
        LIGHT_VERTEX(hold) {
            if (hold) {
                throughput /= 1.0 - p_smooth;
                hold_visible_point(i, s, sh, wo, throughput, p_smooth > 0.0, eye_bounces);
                held = true;
            }
#ifdef DIRECT_LIGHT_SAMPLED
            GLOSSY_LIGHT_NUMBERS(hold);
            ADD_LIGHT(sampled, LIGHT_GROUP_SAMPLED, throughput * direct_light_sampled_lobes(
                          s.material, s.position, s.geometric_normal, sh, wo, p_smooth > 0.0,
                          light_numbers.pick, light_numbers.u, u_dir, FOLLOWED(hold), rays));
#endif
            if (hold) break;
        }
        vec3 dir, sampled;
        if (!bsdf_sample_smooth(sh, wo, u_dir, dir, sampled)) break;
        throughput *= sampled / p_smooth;
        dir = on_the_lobes_side(dir, sh, s.geometric_normal);
        GLOSSY_MIS_LEAVE();
        int kind = sh.kind;
        eye_bounces = bounces_add(eye_bounces, smooth_bounce_kind(sh, wo, dir, s.geometric_normal));
        last_surface = !bounces_within(eye_bounces);
#ifdef FILM_TRANSPARENT
        through_glass = through_glass && kind == MATERIAL_DIELECTRIC &&
                        dot(dir, s.geometric_normal) * dot(ray.dir, s.geometric_normal) > 0.0;
#endif
        ray = make_ray(offset_origin(s.position, s.geometric_normal, dir), dir);
        if (kind == MATERIAL_TRANSPARENT && seen_by_camera) continue;  // sees past a cut-out
        SET_EYE_LINK_RECEIVER(s.material);
        seen_by_camera = false;
    }
    if (!held) hold_no_visible_point(i, eye_bounces);
    add_direct_light(i, vec4(direct, transparent));  // the transparency's sum rides in w
#ifdef PASS_STRIDE
    store_eye_passes(i, passes);
#endif
#ifdef DENOISING_FEATURES
    store_denoising_passes(i, features);
#endif
    rng_store(i, rng);
    atomicAdd(pass_rays, rays);
}
#endif
