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
        Hit hit = closest_hit(make_ray(origin, dir));
        if (hit.triangle < 0) break;
        Surface s = surface_at(make_ray(origin, dir), hit);
#ifdef HAS_ABSORPTION
        flux *= segment_transmittance(s.material, dot(dir, s.geometric_normal) < 0.0, origin,
                                      s.position);
#endif
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
        vec3 wi, w;
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
        if (surfaces == max_bounces || !bsdf_sample(sh, -dir, u_dir, true, wi, w)) break;
        w *= mix_weight;
        float q = min(1.0, max_component(w) / photon_refraction_factor(sh, wi));
        if (!(rng_next(rng) < q)) break;
        flux *= w / q;
        flux *= adjoint_shading_factor(-dir, wi, sh, s.geometric_normal);
        wi = on_the_lobes_side(wi, sh, s.geometric_normal);
        uint kind = photon_bounce_kind(sh, -dir, wi, s.geometric_normal, u_dir);
        path_bounces = photon_bounces_scattered(path_bounces, kind);
        if (!photon_bounces_useful(path_bounces)) break;
        dir = wi;
        origin = offset_origin(s.position, s.geometric_normal, dir);
    }
    rng_store(state_index, rng);
    atomicAdd(pass_rays, rays);
}
#endif
#endif
