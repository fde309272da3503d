// VCM's vertex merging (vcm_techniques "pt+lt+vm", VCM_MERGING; docs/vcm.md), weighted against
// path tracing by the balance heuristic over the paths both sample: light seen through a
// mirror or glass on a rough surface that is itself lit through one, L S+ D S+ E, with D of
// a material vcm_connectable takes (one leaf that only reflects, no smooth lobe, no normal
// map). Light tracing cannot sample these (its camera connection does not cross glass), the
// light sample neither (its shadow ray does not): path tracing finds them only where its
// BSDF sample at D, followed through the smooth vertices, meets the emitter, which for a
// small light is a firefly. Merging takes them at D from the light's side: each light path
// stores its first rough vertex after one or more smooth ones as a photon (its dVC there,
// common/vcm_light_paths.glsl), each eye path holds its first rough vertex after one or more
// smooth ones as a visible point (common/vcm_eye_paths.glsl), and the gather weighs each
// photon there by 1 / (1 + dVC p_rev / (n_L pi r^2)) (n_L pi r^2 = 1 / pass_scale, the pass's
// radius r as PPPM's). The eye path's BSDF sample past D carries the merging's quantity,
// n_L pi r^2 |cos_out| / p_fwd, through the smooth vertices to the emission it meets, which
// weighs 1 / (1 + p_e lt) exactly as light tracing's (vcm_mis.glsl). Every other path is as
// under "pt+lt": merging samples only these.
#ifndef VCM_MERGING_GLSL
#define VCM_MERGING_GLSL
#ifdef VCM_MERGING

// A stored photon's incoming direction carries its dVC as its length (the record has no free
// word): scaled so, and read back without overflow for any float dVC. dVC 0 (a light no eye
// path meets: its merges weigh 1) is stored as the smallest normal float's order.
vec3 vcm_merge_incoming(vec3 incoming, float dvc) {
    return incoming * max(dvc, 1e-30);
}

#ifdef USES_PHOTONS
float photon_merge_dvc(uint p) {
    vec3 v = photon_record(p, PHOTON_INCOMING).xyz;
    float m = max(max(abs(v.x), abs(v.y)), abs(v.z));
    return m > 0.0 ? m * length(v / m) : 0.0;
}

vec3 photon_incoming(uint p) {
    vec3 v = photon_record(p, PHOTON_INCOMING).xyz;
    float m = max(max(abs(v.x), abs(v.y)), abs(v.z));
    return m > 0.0 ? normalize(v / m) : v;
}

// Photon p's weight at a visible point of shading sh seen from wo (gather.comp).
float vcm_merge_weight(uint p, Shading sh, vec3 wo) {
    float p_reverse = bsdf_pdf(sh, wo, photon_incoming(p));
    return 1.0 / (1.0 + photon_merge_dvc(p) * p_reverse * pass_scale);
}
#endif

// The eye path's quantity past its merging vertex, left along dir (p_fwd = bsdf_pdf(sh, wo,
// dir)): n_L pi r^2 |cos_out| / p_fwd.
float vcm_merge_lt(vec3 ng, Shading sh, vec3 wo, vec3 dir) {
    float p_forward = bsdf_pdf(sh, wo, dir);
    return p_forward > 0.0 && pass_scale > 0.0
               ? abs(dot(dir, ng)) / (p_forward * pass_scale)
               : 0.0;
}

#endif
#endif
