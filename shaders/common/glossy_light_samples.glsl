// Light samples at the glossy vertices the eye path follows (GLOSSY_LIGHT_SAMPLES): a metal,
// a plastic's coat or a glass of roughness in (0, glossy_threshold) is not a visible point
// (gathering photons through a narrow lobe is noisy), so the eye path goes on by sampling
// the lobe. Before, that continuation was the vertex's only estimate of its direct light: a
// small lamp was found by chance (a glossy highlight of sparse fireflies), and a sun or a
// point light of radius 0, which no ray can hit, left no highlight at all. Now the vertex
// also takes a light sample, and the two are combined by multiple importance sampling with
// the balance heuristic (Veach 1997, section 9.2), as a path tracer does at every vertex:
//   light sample:     f Le |cos| / p_L  *  p_L / (p_L + p_B)
//   continuation:     f Le |cos| / p_B  *  p_B / (p_L + p_B)   where the ray meets an emitter
// with p_B the density the continuation drew its direction with (the followed lobe's, times
// the probability of following it) and p_L the light sample's for the same direction. Lights
// the continuation cannot meet (suns, points of radius 0, triangles of instanced meshes,
// which the emitter table does not number) keep the light sample's whole weight. The shading
// normal's cosine is used on both sides, as the continuation's weight (bsdf_sample) has it.
//
// common/light_sampling.glsl includes this file just before direct_light_sampled_lobes, which
// takes the light sample (its `followed` mode) with what is defined here.
#ifndef GLOSSY_LIGHT_SAMPLES_GLSL
#define GLOSSY_LIGHT_SAMPLES_GLSL

// The continuation's state, from the last vertex that drew its direction: the density it
// drew it with (0 after a delta lobe, and at the camera: the emission met counts whole), the
// vertex, and the side and transmission environment_light_pdf reads there. Cut-outs and
// the surfaces the eye path passes through leave it as it is.
float glossy_mis_pdf = 0.0;
vec3 glossy_mis_origin = vec3(0.0);
vec3 glossy_mis_side = vec3(0.0, 0.0, 1.0);
bool glossy_mis_transmits = false;

// Whether the lobe the eye path follows here has an f to evaluate (a roughness above 0).
bool glossy_followed_lobe(Shading sh) {
    return sh.roughness > 0.0 && (sh.kind == MATERIAL_CONDUCTOR ||
                                  sh.kind == MATERIAL_DIELECTRIC || sh.kind == MATERIAL_PLASTIC);
}

// f of the followed part and the continuation's density of wi: the whole material for a
// metal or a glass, the coat alone for a plastic, whose coat is followed with probability
// p_smooth (bsdf_sample_smooth draws within the coat).
float glossy_followed_f_pdf(Shading sh, vec3 wo_world, vec3 wi_world, float p_smooth,
                            out vec3 f) {
#ifdef HAS_ROUGH_LOBES
    if (sh.kind == MATERIAL_PLASTIC) {
        vec3 wo = to_local(sh, wo_world), wi = to_local(sh, wi_world);
        f = plastic_layer_f(sh, wo, wi);
        return wo.z > 0.0 && wi.z > 0.0 ? p_smooth * plastic_layer_pdf(sh, wo, wi) : 0.0;
    }
#endif
    f = bsdf_f(sh, wo_world, wi_world, false, false);
    return bsdf_pdf(sh, wo_world, wi_world);
}

// The density with which sample_light draws wi from point or spot light k (a sphere or a
// disc facing p, common/light_sampling.glsl) at p: its pick probability over the cone's
// solid angle, or d^2 / (pi r^2 cos_l) through the disc; 0 where none of it lies along wi.
float sphere_light_pdf(uint k, vec3 p, vec3 wi) {
    vec4 a = emitter_record(k, EMITTER_A), b = emitter_record(k, EMITTER_B);
    vec4 c = emitter_record(k, EMITTER_C);
    int kind = floatBitsToInt(a.w) & EMITTER_KIND_MASK;
    float r = kind == EMITTER_POINT ? b.w : c.y;
    bool disc = kind == EMITTER_POINT ? b.x > 0.5 : spot_facing_disc(c.z);
    vec3 to = a.xyz - p;
    float d2 = dot(to, to);
    if (!(r > 0.0) || !(d2 > r * r)) return 0.0;
    float pick = light_sample_pick(k);
    if (!disc) {
        float cos_max = sqrt(max(0.0, 1.0 - r * r / d2));
        return dot(wi, to) >= cos_max * sqrt(d2) ? pick / (2.0 * PI * (1.0 - cos_max)) : 0.0;
    }
    vec3 facing = -to * inversesqrt(d2);  // the disc's normal, towards p
    float cos_l = dot(facing, -wi);
    if (!(cos_l > 0.0)) return 0.0;
    float t = dot(to, facing) / -cos_l;  // where wi meets the disc's plane
    vec3 off = p + t * wi - a.xyz;
    return dot(off, off) <= r * r ? pick * t * t / (PI * r * r * cos_l) : 0.0;
}

// p_L of a direction wi from emitter k at `distance` (whatever p_L a kind has; 0 where the
// light sample cannot draw wi).
float glossy_light_pdf(uint k, vec3 p, vec3 wi, float distance) {
    int kind = emitter_kind(k);
#ifdef HAS_EMITTER_MIS
    if (kind == EMITTER_TRIANGLE) return triangle_light_pdf(k, wi, distance);
#endif
#ifdef HAS_ENVIRONMENT
    if (kind == EMITTER_ENVIRONMENT)
        return environment_light_pdf(wi, glossy_mis_side, glossy_mis_transmits);
#endif
#ifdef SPHERE_LIGHT_RECORDS
    if (kind == EMITTER_POINT || kind == EMITTER_SPOT) return sphere_light_pdf(k, p, wi);
#endif
    return 0.0;
}

// Whether the continuation can meet emitter k's light at all (else its light sample weighs 1).
bool glossy_continuation_meets(uint k) {
    int kind = emitter_kind(k);
#ifdef HAS_EMITTER_MIS
    if (kind == EMITTER_TRIANGLE) return true;
#endif
#ifdef HAS_ENVIRONMENT
    if (kind == EMITTER_ENVIRONMENT) return true;
#endif
#ifdef SPHERE_LIGHT_RECORDS
    if (kind == EMITTER_POINT || kind == EMITTER_SPOT) return true;
#endif
    return false;
}

// Where direct_light_sampled_lobes takes a followed vertex's light sample: the side and
// transmission the world's density is read with there, kept for the continuation's weight.
void glossy_mis_at(vec3 ng_wo, bool transmits) {
    glossy_mis_side = ng_wo;
    glossy_mis_transmits = transmits;
}

// The weight of a followed vertex's unshadowed light sample ls from emitter `picked` at p,
// against the continuation's density p_followed of the same direction. Triangles the
// continuation meets without a number in the emitter table (two levels: no HAS_EMITTER_MIS)
// are left to the continuation alone (0 here, 1 there).
float glossy_light_weight(uint picked, vec3 p, LightSample ls, float p_followed) {
    int kind = emitter_kind(picked);
#ifndef HAS_EMITTER_MIS
    if (kind == EMITTER_TRIANGLE) return 0.0;
#endif
    if (!glossy_continuation_meets(picked)) return 1.0;
    float p_light = glossy_light_pdf(picked, p, ls.wi, ls.distance);
    return p_light > 0.0 ? p_light / (p_light + p_followed) : 0.0;
}

// After the eye path drew its next direction wi at a followed vertex: the density the
// continuation's emission weighs against (0 after a delta lobe; a cut-out keeps the last).
void glossy_mis_leave(Shading sh, vec3 wo, vec3 wi, float p_smooth, vec3 p, bool sampled) {
    if (sh.kind == MATERIAL_TRANSPARENT) return;
    glossy_mis_pdf = 0.0;
    if (!sampled) return;
    vec3 f;
    glossy_mis_pdf = glossy_followed_f_pdf(sh, wo, wi, p_smooth, f);
    glossy_mis_origin = p;
}

// The world's record in the emitter table (its last), or -1.
int world_emitter() {
#ifdef HAS_ENVIRONMENT
    if (emitter_count > 0u && emitter_kind(emitter_count - 1u) == EMITTER_ENVIRONMENT)
        return int(emitter_count - 1u);
#endif
    return -1;
}

// The weight of emission the continuation meets along `dir` at q: emitter k's (a triangle's
// or a sphere light's record, or the world's), against its light sample at the last glossy
// vertex. 1 where that vertex took none, or where the emitter has no record (k < 0).
float glossy_emission_weight(int k, vec3 dir, vec3 q) {
    if (!(glossy_mis_pdf > 0.0) || k < 0) return 1.0;
    light_pick_at(glossy_mis_origin);  // the light sample's pick there
    float p_light =
        glossy_light_pdf(uint(k), glossy_mis_origin, dir, length(q - glossy_mis_origin));
    return glossy_mis_pdf / (glossy_mis_pdf + p_light);
}

#endif
