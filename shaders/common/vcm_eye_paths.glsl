// VCM's eye subpaths (ESTIMATOR_VCM; docs/vcm.md), spliced into eye_trace.comp in place of
// its visible points' main, whose helpers (camera_ray, add_direct_light, ...) it uses. So
// far its first technique: unidirectional path tracing. Each pixel traces one path a pass,
// its light summed in the pixel's direct-light sum (the film: the mean of the passes).
//
// At every rough vertex (the lobes an SPPM eye path would hold a visible point on) the
// path takes the whole direct light of common/light_sampling.glsl (a light sample, and at
// glossy lobes and for the world one BSDF sample, combined by the balance heuristic) and
// goes on by a BSDF sample of those lobes. The emission that sample's ray meets next (the
// surfaces it passes through as a shadow ray does included) is the direct light already
// counted, so it is left out there; after a smooth bounce (mirror, glass, a smooth coat)
// the emission met is counted, as no light sample reaches it. Russian roulette from the
// fourth scatter on, on the path's throughput; Cycles' Light Paths limits as the eye stage
// counts them (common/bounces.glsl): a rough vertex takes its direct light while its
// scatters so far are within them, and the path ends where the next scatter is not.
#ifndef VCM_EYE_PATHS_GLSL
#define VCM_EYE_PATHS_GLSL

#ifdef ESTIMATOR_VCM
#ifndef DIRECT_LIGHT_SAMPLED
#error "ESTIMATOR_VCM takes its direct light from light sampling (direct_light sampled)"
#endif

// Scatters after which Russian roulette plays.
const uint VCM_ROULETTE_AFTER = 3u;

// Where a path leaves a rough vertex: a sample of the whole material (rough_only false), or
// of its rough lobes alone where a smooth part is followed by the path instead (a plastic's
// diffuse base under a smooth coat): cosine-weighted about the shading normal, weight
// f cos / pdf = pi f. False where the sample carries nothing.
bool vcm_rough_sample(Shading sh, vec3 wo, bool rough_only, vec3 u, out vec3 wi,
                      out vec3 weight) {
    if (!rough_only) return bsdf_sample(sh, wo, u, false, wi, weight);
    wi = sample_cosine_hemisphere(sh.n, u.x, u.y);
    weight = bsdf_f(sh, wo, wi, true, false) * PI;
    return dot(wi, sh.n) > 0.0 && any(greaterThan(weight, vec3(0.0)));
}

#ifdef VCM_MIS
// The eye path's light tracing quantity lt (common/vcm_mis.glsl) past the rough vertex s,
// left along dir: at the first vertex y1, where light tracing connects to the camera,
// n_L / p_camera(y1) |cos_out| / p_fwd; at each rough vertex past it where light paths
// scatter as well (vcm_connectable), lt_here p_rev |cos_out| / p_fwd, p_rev the density of
// the light's side (the direction back to wo from dir); 0 elsewhere.
float vcm_lt_past_rough(Surface s, Shading sh, vec3 wo, vec3 dir, bool first, vec3 lens_point,
                        float lt_here) {
    if (!vcm_connectable(s, sh, wo)) return 0.0;
    float lt_scatter = lt_here * bsdf_pdf(sh, dir, wo);
    if (first) {
        vec3 from_camera = s.position - lens_point;
        float distance = length(from_camera);
        float p_camera = vcm_camera_area_pdf(from_camera / distance, distance,
                                             abs(dot(wo, s.geometric_normal)));
        lt_scatter = p_camera > 0.0 ? float(photon_threads) / p_camera : 0.0;
    }
    float p_forward = lt_scatter > 0.0 ? bsdf_pdf(sh, wo, dir) : 0.0;
    return p_forward > 0.0 ? lt_scatter * abs(dot(dir, s.geometric_normal)) / p_forward : 0.0;
}
#endif

// The world's radiance the eye path meets along dir as it leaves the scene; with VCM_MIS
// weighed against light tracing's paths by lt, the path's quantity there.
vec3 vcm_world_met(vec3 dir, float lt) {
    vec3 world = environment_radiance(dir);
#if defined(VCM_MIS) && defined(HAS_ENVIRONMENT)
    world *= vcm_world_emission_weight(dir, lt);
#endif
    return world;
}

#ifdef SPHERE_LIGHT_RECORDS
// Whether the ray meets a point or spot light's sphere before the surface it hits, and its
// radiance there, with VCM_MIS weighed against light tracing's paths by lt.
bool vcm_sphere_light_met(Ray ray, Hit hit, float lt, out vec3 radiance) {
    if (!sphere_light_before_hit(ray, hit, radiance)) return false;
#ifdef VCM_MIS
    radiance *= vcm_sphere_emission_weight(lt);
#endif
    return true;
}
#endif

#ifdef FILM_TRANSPARENT
// Blender's Film > Transparent as eye_trace's main has it: a ray leaving the scene is the
// film's transparency (its sum rides in the film's w) where the camera sees it directly or
// (FILM_TRANSPARENT_GLASS) through glass alone, which a smooth transmission through a
// dielectric keeps and any other bounce ends.
#define VCM_LEAVES_THROUGH_FILM() \
    if (leaves_through_film(seen_by_camera, through_glass, throughput, transparent)) break
#define VCM_THROUGH_GLASS(smooth, dir)                                                \
    through_glass = through_glass && (smooth) && sh.kind == MATERIAL_DIELECTRIC &&   \
                    dot(dir, s.geometric_normal) * dot(ray.dir, s.geometric_normal) > 0.0
#else
#define VCM_LEAVES_THROUGH_FILM()
#define VCM_THROUGH_GLASS(smooth, dir)
#endif

// Light the path takes into the pixel's sum (VCM_ADD_LIGHT): with light groups
// (common/light_groups.glsl) into its emitter's group's too, by the group code: an emissive
// material's (material_group_code), the world's, a sphere light's (sphere_light_group_code),
// or LIGHT_GROUP_SAMPLED for a light sample, whose parts direct_light_sampled_lobes hands
// over itself, times the throughput set here first.
#ifdef LIGHT_GROUPS
#define VCM_ADD_LIGHT(code, value)           \
    {                                        \
        light_group_throughput = throughput; \
        vec3 light_ = (value);               \
        light += light_;                     \
        light_group_add(code, light_);       \
    }
#define VCM_GROUP_OF(m) material_group_code(m)
#define VCM_GROUP_SPHERE sphere_light_group_code
#define VCM_GROUP_WORLD WORLD_GROUP_CODE
#define VCM_GROUP_SAMPLED LIGHT_GROUP_SAMPLED
#else
#define VCM_ADD_LIGHT(code, value) light += (value)
#define VCM_GROUP_OF(m) 0u
#define VCM_GROUP_SPHERE 0u
#define VCM_GROUP_WORLD 0u
#define VCM_GROUP_SAMPLED 0u
#endif

// Render passes (docs/passes.md) under VCM: the eye stage's EyePasses (Depth and Normal of
// the first surface the camera sees; Emission and Environment seen before the path's first
// rough scatter, as SPPM's eye paths see them) and its denoising features (every surface
// while they are pending, and the light seen on the way), stored with the light groups
// (store_eye_passes). The light split (Direct, Indirect, Caustics) is refused (settings).
#ifdef PASS_STRIDE
#define VCM_EYE_PASSES_BEGIN_() EyePasses passes = start_eye_passes()
#define VCM_EYE_PASSES_END_(i) store_eye_passes(i, passes)
#define VCM_NOTE_SURFACE(s, front) note_first_surface(passes, s, front)
#define VCM_PASS_PART(part, value) \
    if (!rough_met) passes.part += (value)
#else
#define VCM_EYE_PASSES_BEGIN_()
#define VCM_EYE_PASSES_END_(i)
#define VCM_NOTE_SURFACE(s, front)
#define VCM_PASS_PART(part, value)
#endif
#ifdef DENOISING_FEATURES
#define VCM_FEATURES_BEGIN_() DenoisingFeatures features = start_denoising_features()
#define VCM_FEATURES_END_(i) store_denoising_passes(i, features)
#define VCM_FEATURE_SURFACE(s, sh, wo) add_feature_surface_at(features, s, sh, wo)
#define VCM_FEATURE_LIGHT(radiance) add_feature_light(features, radiance)
#else
#define VCM_FEATURES_BEGIN_()
#define VCM_FEATURES_END_(i)
#define VCM_FEATURE_SURFACE(s, sh, wo)
#define VCM_FEATURE_LIGHT(radiance)
#endif
#define VCM_PASSES_BEGIN() \
    VCM_EYE_PASSES_BEGIN_(); \
    VCM_FEATURES_BEGIN_()
#define VCM_PASSES_END(i) \
    VCM_EYE_PASSES_END_(i); \
    VCM_FEATURES_END_(i)
// Emission or the world the path meets, of this radiance, times its throughput: in the
// pixel's sum, its group's, its pass (part: emitted or world) and the denoising albedo's.
#define VCM_SEE(part, code, radiance)                \
    {                                                \
        vec3 seen_ = (radiance);                     \
        VCM_ADD_LIGHT(code, throughput * seen_);     \
        VCM_PASS_PART(part, throughput * seen_);     \
        VCM_FEATURE_LIGHT(seen_);                    \
    }
#define VCM_SEE_EMISSION(m, radiance) VCM_SEE(emitted, VCM_GROUP_OF(m), radiance)

// Russian roulette on the path's throughput from the fourth scatter on: false where it ends.
bool vcm_roulette(inout vec3 throughput, uint scatters, inout RNG_STATE rng) {
    if (scatters <= VCM_ROULETTE_AFTER) return true;
    float q = min(1.0, max_component(throughput));
    if (!(rng_next(rng) < q)) return false;
    throughput /= q;
    return true;
}

#ifdef VCM_MERGING
// Vertex merging (common/vcm_merging.glsl): the path's first rough vertex after one or more
// smooth ones (not a cut-out seen through), of a material both sides merge at, is held as
// the pixel's visible point, which gathers the light paths' photons there; past it the
// path's BSDF sample carries the merging's quantity to the emission it meets through smooth
// vertices and the rough vertices light paths pass (vcm_lt_past_rough), up to the light
// paths' last stored slot (u_merge_slots): the light path of a longer path stores no
// vertex where this path merged, so there it is path tracing's alone.
uniform uint u_merge_slots;
#define VCM_HOLD_MERGE_POINT()                                                      \
    bool merge_here = !seen_by_camera && !rough_met && vcm_connectable(s, sh, wo); \
    if (merge_here) {                                                              \
        hold_visible_point(i, s, sh, wo, throughput, false, eye_bounces);          \
        held = true;                                                               \
    } else if (held) {                                                             \
        ++rough_past_merge;                                                        \
    }
#define VCM_MERGE_LT()                                                \
    if (merge_here) lt = vcm_merge_lt(s.geometric_normal, sh, wo, dir); \
    else if (rough_past_merge >= u_merge_slots) lt = 0.0
#else
#define VCM_HOLD_MERGE_POINT()
#define VCM_MERGE_LT()
#endif

// The path's light as the film takes it, at its end: with merging and no visible point held,
// the pixel's none this pass; for the tests' parts one technique's share alone.
// With light groups, the parts clear theirs as well (stored with the passes).
#ifdef LIGHT_GROUPS
#define VCM_GROUPS_CLEAR() light_groups_begin()
#else
#define VCM_GROUPS_CLEAR()
#endif
vec3 vcm_path_end(uint i, uint eye_bounces, bool held, vec3 light) {
#ifdef VCM_MIS_LIGHT_PART
    light = vec3(0.0);  // the light side's weighted part alone ("pt+lt:light")
    VCM_GROUPS_CLEAR();
#endif
#ifdef VCM_MERGING
    if (!held) hold_no_visible_point(i, eye_bounces);
#ifdef VCM_MERGE_PART
    light = vec3(0.0);  // the merges alone ("pt+lt+vm:merge")
    VCM_GROUPS_CLEAR();
#endif
#endif
    return light;
}

// One eye path (with merging, rough_met: a rough vertex met; held: the visible point held;
// rough_past_merge: the rough vertices past it). seen_by_camera: no scatter yet;
// last_surface: past a limit, the next surface's emission ends the path; after_rough: the
// last scatter was rough, whose direct light holds the emission met next. With VCM_MIS, lt:
// light tracing's partial quantity past the first vertex y1 (common/vcm_mis.glsl,
// vcm_lt_past_rough), or merging's past its vertex (vcm_merge_lt), divided by the cosine at
// each surface met (lt_here); 0 where neither can sample the path.
void main() {
    uint i = thread_index();
    if (i >= image_width * image_height) return;
    RNG_STATE rng = load_pixel_rng(i);
    Ray ray = camera_ray(i % image_width, i / image_width, rng);
    vec3 throughput = vec3(1.0), light = vec3(0.0);
    uint rays = 0u, eye_bounces = 0u, scatters = 0u, rough_past_merge = 0u;
    bool seen_by_camera = true, last_surface = false, after_rough = false;
    bool rough_met = false, held = false;  // a rough vertex met; VCM_MERGING: held
    float lt = 0.0;  // VCM_MIS
    VCM_PASSES_BEGIN();  // with light groups, their sums too
    float transparent = 0.0; bool through_glass = true;  // FILM_TRANSPARENT, as eye_trace's
    vec3 lens_point = ray.origin;  // VCM_MIS
    for (uint depth = 0u; depth <= max_bounces; ++depth) {  // surfaces, as eye_trace's
        ++rays;
        Hit hit = closest_hit(ray);
#ifdef SPHERE_LIGHT_RECORDS
        vec3 sphere_radiance;
        if (!seen_by_camera && vcm_sphere_light_met(ray, hit, lt, sphere_radiance)) {
            if (!after_rough) VCM_SEE(emitted, VCM_GROUP_SPHERE, sphere_radiance);
            break;
        }
#endif
        if (hit.triangle < 0) {
            VCM_LEAVES_THROUGH_FILM();
            if (!after_rough) VCM_SEE(world, VCM_GROUP_WORLD, vcm_world_met(ray.dir, lt));
            break;
        }
        Surface s = surface_at(ray, hit);
        bool front = dot(ray.dir, s.geometric_normal) < 0.0;
        int flags = material_flags(s.material);
        bool hidden = (flags & (seen_by_camera ? MATERIAL_HIDDEN_FROM_CAMERA
                                               : MATERIAL_HIDDEN_FROM_REFLECTIONS)) != 0;
        if (hidden && (flags & MATERIAL_LIGHT_SURFACE) == 0) {
            ray = make_ray(offset_origin(s.position, s.geometric_normal, ray.dir), ray.dir);
            continue;
        }
#ifdef HAS_ABSORPTION
        throughput *= segment_transmittance(s.material, front, ray.origin, s.position);
#endif
        float emission_weight = 1.0;  // against light tracing's paths (VCM_MIS)
#ifdef VCM_MIS
        float lt_here = lt / max(abs(dot(ray.dir, s.geometric_normal)), 1e-30);
        emission_weight = vcm_emission_weight(hit.triangle, -ray.dir, lt_here);
#endif
        if ((flags & MATERIAL_LIGHT_SURFACE) != 0) {
            if (front && !hidden && !after_rough)
                VCM_SEE_EMISSION(s.material, material_emission(s.material) * emission_weight);
            ray = make_ray(offset_origin(s.position, s.geometric_normal, ray.dir), ray.dir);
            continue;
        }
        VCM_NOTE_SURFACE(s, front);
        vec3 wo = -ray.dir;
        Shading sh = shading_at(s.material, s.normal, s.geometric_normal, texture_point(s),
                                s.vertex_color, wo, rng_next(rng));
        if ((front || (flags & MATERIAL_ONE_SIDED_EMISSION) == 0) && !after_rough)
            VCM_SEE_EMISSION(s.material, emission_weight * material_emission_at(
                                             s.material, sh.material, texture_point(s)));
        VCM_FEATURE_SURFACE(s, sh, wo);
        if (last_surface) break;
        float p_smooth = bsdf_smooth_probability(sh, wo);
        float u_lobe = rng_next(rng);
        vec3 u_dir = vec3(rng_next(rng), rng_next(rng), rng_next(rng));
        vec3 dir, weight;
        bool smooth_bounce = u_lobe < p_smooth;
        uint kind;
        if (smooth_bounce) {
            if (!bsdf_sample_smooth(sh, wo, u_dir, dir, weight)) break;
            throughput *= weight / p_smooth;
            dir = on_the_lobes_side(dir, sh, s.geometric_normal);
            kind = smooth_bounce_kind(sh, wo, dir, s.geometric_normal);
#ifdef VCM_MIS
            // Light tracing follows a smooth vertex where its leaf is smooth alone.
            lt = p_smooth >= 1.0 ? lt_here * abs(dot(dir, s.geometric_normal)) : 0.0;
#endif
        } else {
#if defined(VCM_LIGHT_TRACING) && !defined(VCM_MIS)
            break;  // light tracing alone: the light subpaths take what reaches this vertex
#endif
            throughput /= 1.0 - p_smooth;
            bool rough_only = p_smooth > 0.0;
            VCM_HOLD_MERGE_POINT();
            rough_met = true;
            LightSampleNumbers n = draw_light_sample_numbers(rng);
            vec3 u_mis = vec3(rng_next(rng), rng_next(rng), rng_next(rng));
            VCM_ADD_LIGHT(VCM_GROUP_SAMPLED,
                          throughput * direct_light_sampled_lobes(
                              s.material, s.position, s.geometric_normal, sh, wo, rough_only,
                              n.pick, n.u, u_mis, 0.0, rays));
            if (!vcm_rough_sample(sh, wo, rough_only, u_dir, dir, weight)) break;
            throughput *= weight;
            dir = on_the_lobes_side(dir, sh, s.geometric_normal);
#ifdef VCM_MIS
            lt = vcm_lt_past_rough(s, sh, wo, dir, seen_by_camera, lens_point, lt_here);
            VCM_MERGE_LT();
#endif
            kind = bounce_kind(wo, dir, s.geometric_normal,
                               rough_only || bsdf_sample_is_diffuse(sh, wo, u_dir));
        }
        VCM_THROUGH_GLASS(smooth_bounce, dir);
        eye_bounces = bounces_add(eye_bounces, kind);
        bool within = bounces_within(eye_bounces);
        // Past a limit: a smooth bounce still takes the emission it meets, a rough one's
        // emission is its direct light, already counted.
        if (!within && !smooth_bounce) break;
        last_surface = !within;
        if (kind != BOUNCE_NONE) {  // a cut-out passed through is no scatter
            ++scatters;
            after_rough = !smooth_bounce;
        }
        if (!vcm_roulette(throughput, scatters, rng)) break;
        ray = make_ray(offset_origin(s.position, s.geometric_normal, dir), dir);
        if (kind != BOUNCE_NONE) seen_by_camera = false;
    }
    add_direct_light(i, vec4(vcm_path_end(i, eye_bounces, held, light), transparent));
    VCM_PASSES_END(i);
    rng_store(i, rng);
    atomicAdd(pass_rays, rays);
}
#endif
#endif
