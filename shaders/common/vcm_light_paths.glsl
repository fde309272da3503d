// VCM's light subpaths (ESTIMATOR_VCM with VCM_LIGHT_TRACING; docs/vcm.md), spliced into
// photon_trace.comp in place of its one-bounce photon main, whose helpers (load_photon_rng,
// photon_bounce_kind, adjoint_shading_factor, LENS_NUMBERS) it uses. Its technique: light
// tracing (t = 1). One light path a photon thread and pass, traced whole in one dispatch:
// emitted as the photons are (emit_photon), scattered and ended as they are (the material's
// sample, Russian roulette on the sample's weight, Cycles' Light Paths limits as the
// photons count them, at most max_bounces + 1 surfaces). Every vertex where light tracing
// can evaluate the eye's f (common/light_tracing.glsl: light_traceable, connection_f) is
// connected to the camera and splatted into the fixed-point film (common/light_splats.glsl),
// the path's first vertex (direct light) included; light_splats.comp divides a pass's splats
// by its paths (photon_threads) and the film takes the mean of the passes.
//
// Light tracing alone (vcm_techniques "lt") covers the paths whose vertex next to the eye is
// such a rough vertex; the eye path (common/vcm_eye_paths.glsl) then keeps only the emission
// it meets before any rough scatter (L S* E). Paths seen through a mirror or glass from a
// rough vertex (L ... D S+ E) and those ending on glass or translucent leaves or on
// normal-mapped surfaces (not light_traceable) are in neither: the technique alone is
// unbiased only where the scene has none of them (the tests' scenes). Not MIS-weighted yet.
#ifndef VCM_LIGHT_PATHS_GLSL
#define VCM_LIGHT_PATHS_GLSL

#if defined(ESTIMATOR_VCM) && defined(VCM_LIGHT_TRACING)
// The surface a light path meets next from origin along dir, its flux through the medium
// it crossed (absorption); false where it leaves the scene.
bool light_path_next_surface(vec3 origin, vec3 dir, inout vec3 flux, out Surface s) {
    Hit hit = closest_hit(make_ray(origin, dir));
    if (hit.triangle < 0) return false;
    s = surface_at(make_ray(origin, dir), hit);
#ifdef HAS_ABSORPTION
    flux *= segment_transmittance(s.material, dot(dir, s.geometric_normal) < 0.0, origin,
                                  s.position);
#endif
    return true;
}

// The light path's scatter at s by the material's sample u_dir (the photons' own: Russian
// roulette on the sample's weight by u_survive, Cycles' Light Paths limits as the photons
// count them): dir and flux become the next segment's, false where the path ends.
bool light_path_scatter(Surface s, Shading sh, vec3 u_dir, float mix_weight, float u_survive,
                        inout vec3 dir, inout vec3 flux, inout uint path_bounces) {
    vec3 wi, w;
    if (!bsdf_sample(sh, -dir, u_dir, true, wi, w)) return false;
    w *= mix_weight;
    float q = min(1.0, max_component(w) / photon_refraction_factor(sh, wi));
    if (!(u_survive < q)) return false;
    flux *= w / q;
    flux *= adjoint_shading_factor(-dir, wi, sh, s.geometric_normal);
    wi = on_the_lobes_side(wi, sh, s.geometric_normal);
    uint kind = photon_bounce_kind(sh, -dir, wi, s.geometric_normal, u_dir);
    path_bounces = photon_bounces_scattered(path_bounces, kind);
    if (!photon_bounces_useful(path_bounces)) return false;
    dir = wi;
    return true;
}
#endif

#if defined(ESTIMATOR_VCM) && defined(VCM_MIS)
// Light tracing weighted against path tracing (vcm_techniques "pt+lt", common/vcm_mis.glsl):
// the light paths of triangle emitters and point lights that begin with one or more smooth
// vertices, followed past smooth and connectable rough vertices (vcm_connectable), splatted
// at each rough one with the weight 1 / (1 + p_camera / n_L dVC p_rev). dVC is the eye path's
// emission hit's share: the cosine at the emitter over its emission densities (area and
// direction), the cosines out over in at the vertices, p_rev over p_fwd at the rough ones
// passed, over the cosine in at the splatting vertex; times the BSDF's density p_rev there
// towards the light (VCM's dVC, its connection terms left out: docs/vcm.md).
void vcm_weighted_splat(Surface s, vec3 dir, vec3 flux, float dvc, uint path_bounces,
                        vec2 lens_u, inout RNG_STATE rng) {
#ifdef VCM_MIS_EYE_PART
    return;  // the eye side's weighted part alone ("pt+lt:eye")
#endif
    uint i;
    vec3 to_camera;
    float distance, cos_surface, importance;
    if (!camera_connection(s, dir, lens_u, i, to_camera, distance, cos_surface, importance))
        return;
    Shading sh = shading_at(s.material, s.normal, s.geometric_normal, texture_point(s),
                            s.vertex_color, to_camera, 0.5);
    if (!vcm_connectable(s, sh, to_camera)) return;
    vec3 f = connection_f(s, dir, to_camera, path_bounces, 0.5);
    if (f == vec3(0.0)) return;
    if (!camera_sees(s.position, s.geometric_normal, to_camera, distance, rng)) return;
    float p_camera = cos_surface * importance / light_splat_pixel_area();
    float p_reverse = bsdf_pdf(sh, to_camera, -dir);
    float weight = 1.0 / (1.0 + p_camera / float(photon_threads) * dvc * p_reverse);
    vec3 splat = flux * f * (cos_surface * importance * weight);
    light_splat_add(i, splat);
#if defined(LIGHT_GROUPS) && defined(USES_PHOTON_PATHS)  // the path's group (emit_photon)
    light_splat_group_add(i, photon_group_code, splat);
#endif
}

#ifdef VCM_MERGING
// Vertex merging's photons (common/vcm_merging.glsl): the light path's rough vertices s after
// one or more smooth ones, the k-th in slot k (photon k photon_threads + i), up to
// u_merge_slots of them, each reached along dir with this flux, its dVC there (over the
// cosine in) stored as its incoming direction's length, its bounce word for the gather's
// Light Paths limits. The slots it does not fill this pass store none.
void vcm_store_merge_photon(uint p, Surface s, Shading sh, vec3 dir, vec3 flux, float dvc,
                            uint path_bounces, inout RNG_STATE rng) {
    vec4 position_key, stored;
    photon_at(s, sh, dir, flux, rng, position_key, stored);
    store_photon_record(p, PHOTON_INCOMING, vec4(vcm_merge_incoming(-dir, dvc),
                                                 photon_record_word(0.0, path_bounces)));
    store_photon_record(p, PHOTON_POSITION, position_key);
    store_photon_record(p, PHOTON_FLUX, stored);
}
#define VCM_NO_MORE_MERGE_PHOTONS(i, stored)                              \
    for (uint slot_ = (stored); slot_ < u_merge_slots; ++slot_)          \
        store_photon_record(slot_ * photon_threads + (i), PHOTON_FLUX, vec4(0.0))
#else
#define VCM_NO_MORE_MERGE_PHOTONS(i, stored)
#endif

void main() {
    uint i = thread_index();
    if (i >= photon_threads) return;
    uint merge_stored = 0u;  // VCM_MERGING: the slots filled
    uint state_index = image_width * image_height + i;
    RNG_STATE rng = load_photon_rng(i, state_index);
    RNG_STATE peek = rng;
    uint k = pick_emitter(rng_next(peek));  // the emitter emit_photon picks with its first number
    vec3 origin, dir, flux;
    emit_photon(rng, origin, dir, flux);
    atomicAdd(pass_emitted, 1u);
    uint rays = 0u;
    float p_direction = vcm_emission_direction_pdf(k, origin, dir);
#ifndef HAS_EMITTER_MIS
    // The eye path cannot tell which triangle emitter it meets: path tracing keeps their light.
    if (emitter_kind(k) == EMITTER_TRIANGLE) p_direction = 0.0;
#endif
    if (p_direction > 0.0 || vcm_unmet_emitter(k)) {
        float dvc = 0.0;  // stays 0 for a point light, a sun, a spot of radius 0
#ifdef HAS_TRIANGLE_EMITTERS
        if (emitter_kind(k) == EMITTER_TRIANGLE) {
            vec3 n = triangle_normal(emitter_record(k, EMITTER_A).xyz,
                                     emitter_record(k, EMITTER_B).xyz,
                                     emitter_record(k, EMITTER_C).xyz);
            dvc = abs(dot(n, dir)) / (vcm_triangle_area_pdf(k) * p_direction);
        }
#endif
#ifdef HAS_POINT_LIGHTS
        // A sphere light: its cosine at the origin over p_A p_dir (a point light's stays 0:
        // no eye path meets it).
        if (emitter_kind(k) == EMITTER_POINT && emitter_record(k, EMITTER_B).w > 0.0)
            dvc = PI / vcm_sphere_area_pdf(k);
#endif
#ifdef HAS_SPOT_LIGHTS
        if (emitter_kind(k) == EMITTER_SPOT && emitter_record(k, EMITTER_C).y > 0.0) {
            origin = vcm_spot_sphere_origin(k, origin, dir);
            dvc = vcm_spot_start(k, p_direction);
        }
#endif
#ifdef HAS_ENVIRONMENT
        // The world: 1 over p_A p_dir (the disc the path leaves faces it).
        if (emitter_kind(k) == EMITTER_ENVIRONMENT)
            dvc = 1.0 / (vcm_world_area_pdf(k) * p_direction);
#endif
        uint path_bounces = 0u, smooth_vertices = 0u;
        for (uint surfaces = 0u; surfaces <= max_bounces; ++surfaces) {
            ++rays;
            Surface s;
            if (!light_path_next_surface(origin, dir, flux, s)) break;
            if ((material_flags(s.material) & MATERIAL_LIGHT_SURFACE) != 0) {
                origin = offset_origin(s.position, s.geometric_normal, dir);  // lights cast none
                continue;
            }
            float cos_in = abs(dot(dir, s.geometric_normal));
            if (!(cos_in > 0.0)) break;
            dvc /= cos_in;
            if (smooth_vertices > 0u)  // L S+ ... D E: direct light is path tracing's alone
                vcm_weighted_splat(s, dir, flux, dvc, path_bounces, LENS_NUMBERS, rng);
            // On past smooth vertices, and past rough ones once a smooth one began the path
            // where both sides weigh them alike (vcm_connectable); elsewhere every path is
            // path tracing's.
            Shading sh = shading_at(s.material, s.normal, s.geometric_normal, texture_point(s),
                                    s.vertex_color, -dir, rng_next(rng));
            vec3 u_dir = vec3(rng_next(rng), rng_next(rng), rng_next(rng));
            float p_smooth = bsdf_smooth_probability(sh, -dir);
            bool rough = p_smooth <= 0.0 && smooth_vertices > 0u && vcm_connectable(s, sh, -dir);
#ifdef VCM_MERGING
            if (rough && merge_stored < u_merge_slots)
                vcm_store_merge_photon(merge_stored++ * photon_threads + i, s, sh, dir, flux, dvc,
                                       path_bounces, rng);
#endif
            vec3 from = -dir;
            if (surfaces == max_bounces || !(p_smooth >= 1.0 || rough) ||
                !light_path_scatter(s, sh, u_dir, 1.0, rng_next(rng), dir, flux, path_bounces))
                break;
            if (rough) {
                // VCM's dVC past a rough vertex: |cos_out| / p_fwd times dVC p_rev, with the
                // densities read from the leaf as the eye path sees it (from the next vertex).
                Shading seen = shading_at(s.material, s.normal, s.geometric_normal,
                                          texture_point(s), s.vertex_color, dir, 0.5);
                // dVC 0 stays 0: a light no eye path meets (vcm_unmet_emitter), whose paths
                // light tracing and merging take whole. (Until session 19 such a path ended
                // here, and with it the light a sun's or a point light's caustic sends on.)
                float p_forward = bsdf_pdf(seen, from, dir);
                if (!(p_forward > 0.0)) break;
                dvc *= bsdf_pdf(seen, dir, from) / p_forward;
            } else {
                ++smooth_vertices;
            }
            dvc *= abs(dot(dir, s.geometric_normal));
            origin = offset_origin(s.position, s.geometric_normal, dir);
        }
    }
    VCM_NO_MORE_MERGE_PHOTONS(i, merge_stored);
    rng_store(state_index, rng);
    atomicAdd(pass_rays, rays);
}
#elif defined(ESTIMATOR_VCM) && defined(VCM_LIGHT_TRACING)
void main() {
    uint i = thread_index();
    if (i >= photon_threads) return;
    uint state_index = image_width * image_height + i;
    RNG_STATE rng = load_photon_rng(i, state_index);
    vec3 origin, dir, flux;
    emit_photon(rng, origin, dir, flux);
    atomicAdd(pass_emitted, 1u);
    uint path_bounces = 0u, rays = 0u;
    for (uint surfaces = 0u; surfaces <= max_bounces; ++surfaces) {
        ++rays;
        Surface s;
        if (!light_path_next_surface(origin, dir, flux, s)) break;
        int flags = material_flags(s.material);
        bool shadowless = (flags & MATERIAL_CASTS_NO_SHADOW) != 0;
        if ((flags & MATERIAL_LIGHT_SURFACE) != 0 ||
            (shadowless && material_kind(s.material) != MATERIAL_DIFFUSE)) {
            origin = offset_origin(s.position, s.geometric_normal, dir);  // lights cast none
            continue;
        }
        Shading sh = shading_at(s.material, s.normal, s.geometric_normal, texture_point(s),
                                s.vertex_color, -dir, rng_next(rng));
        if (light_traceable(s)) {
            float u_leaf = material_kind(s.material) == MATERIAL_MIX ? rng_next(rng) : 0.5;
            splat_to_camera(s, dir, flux, path_bounces, u_leaf, LENS_NUMBERS, rng);
        }
        vec3 u_dir = vec3(rng_next(rng), rng_next(rng), rng_next(rng));
        float mix_weight = 1.0;
#ifdef HAS_ROUGH_LOBES
        if (material_kind(s.material) == MATERIAL_MIX)
            sh = shading_at_by_scatter(s.material, s.normal, s.geometric_normal, texture_point(s),
                                       s.vertex_color, -dir, rng_next(rng), mix_weight);
#endif
        if (shadowless) {  // lit where the path lands, which goes on unchanged
            origin = offset_origin(s.position, s.geometric_normal, dir);
            continue;
        }
        if (surfaces == max_bounces ||
            !light_path_scatter(s, sh, u_dir, mix_weight, rng_next(rng), dir, flux, path_bounces))
            break;
        origin = offset_origin(s.position, s.geometric_normal, dir);
    }
    rng_store(state_index, rng);
    atomicAdd(pass_rays, rays);
}
#endif
#endif
