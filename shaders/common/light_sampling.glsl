// Direct light at a visible point by light sampling (next-event estimation): one emitter
// picked by power from the table photons start from (emitters.glsl), one point or direction
// on it, one shadow ray. The estimate of the reflected direct radiance is
//   f(wo, wi) L_e(wi) cos(theta) / (p_pick p(wi)),
// p(wi) the emitter's own density per solid angle (an area density times d^2 / cos(theta_l)
// where the emitter has a surface: d(omega) = cos(theta_l) dA / d^2), a one-sample Monte
// Carlo estimate of the reflection integral over the emitters (the area form of Kajiya 1986's
// rendering equation). Each record holds power / p_pick, so the estimates below are
// written in that. Used when the photon stage stores only photons that have scattered at
// least once (DIRECT_LIGHT_SAMPLED): the two estimates then split the light at a visible
// point without overlap.
#ifndef LIGHT_SAMPLING_GLSL
#define LIGHT_SAMPLING_GLSL

#include "common/lobes.glsl"
#include "common/emitters.glsl"
#include "common/light_groups.glsl"
#include "common/light_linking.glsl"

// With light groups each part of the result goes to its emitter's group as well
// (common/light_groups.glsl); the parts sum to the result.
#ifdef LIGHT_GROUPS
#define LIGHT_GROUP_PART(code, part) light_group_sampled_add(code, part)
#else
#define LIGHT_GROUP_PART(code, part)
#endif

// Light linking (common/light_linking.glsl): which emitters reach the point, which surfaces
// shadow which emitter. LINK_SHADOW_RAY names the emitter set the next shadow ray is for.
#ifdef LIGHT_LINKING
#define LINK_LIGHT_SAMPLE(m, picked, ls) light_link_sample(m, picked, ls.radiance_over_pdf)
#define LINK_REACHES(set) light_link_reaches(set, light_link_receiver)
#define LINK_SHADOW_RAY(set) shadow_link_set = (set)
// A BSDF sample's ray learns whose light it meets only at its end: it keeps the sets that
// the surfaces it crossed shadow (`link_shadowed`, light_along_bsdf_sample) and counts an
// emitter only where its set is not among them.
#define LINK_UNSHADOWED(set) (((link_shadowed >> (set)) & 1u) == 0u)
#else
#define LINK_LIGHT_SAMPLE(m, picked, ls)
#define LINK_REACHES(set) true
#define LINK_SHADOW_RAY(set)
#define LINK_UNSHADOWED(set) true
#endif

#ifdef BVH_ANY_HIT_FILTER
// The random number a shadow ray crosses cut-outs with (set before any_hit).
uint shadow_ray_seed = 0u;

// Area-light surfaces and objects with shadow visibility off cast no shadow; a cut-out (a
// Mix with a Transparent leaf) lets the shadow ray through where its mix picks that leaf,
// with a number drawn per surface crossed (common/mtbvh.glsl asks this of every hit). The
// mixes' view-dependent factors are taken at normal incidence, and a transparent leaf's
// tint does not colour the shadow.
bool shadow_passes(int m, int triangle, float u, float v) {
    int flags = material_flags(m);
    if ((flags & (MATERIAL_LIGHT_SURFACE | MATERIAL_CASTS_NO_SHADOW)) != 0) return true;
#ifdef LIGHT_LINKING
    if (!shadow_link_blocks_set(m, shadow_link_set)) return true;  // shadow linking
#endif
    if ((flags & MATERIAL_MAY_BE_TRANSPARENT) != 0) {
        vec2 uv = vec2(0.0);
#ifdef HAS_TEXTURES
        vec4 uv01 = vertex_uvs[2 * triangle + 0];
        vec2 uv2 = vertex_uvs[2 * triangle + 1].xy;
        uv = (1.0 - u - v) * uv01.xy + u * uv01.zw + v * uv2;
#endif
        vec3 position = vec3(0.0);
#ifdef HAS_POSITION_TEXTURES
        vec3 p0 = triangles[3 * triangle].xyz;
        position = p0 + u * (triangles[3 * triangle + 1].xyz - p0) +
                   v * (triangles[3 * triangle + 2].xyz - p0);
#endif
        uint h = (shadow_ray_seed ^ uint(triangle) * 0x9E3779B9u) * 747796405u + 2891336453u;
        h = ((h >> ((h >> 28u) + 4u)) ^ h) * 277803737u;
        float r = float(((h >> 22u) ^ h) >> 8) * (1.0 / 16777216.0);
        return material_kind(resolve_mix(m, TexturePoint(uv, position), 1.0, true, r)) == MATERIAL_TRANSPARENT;
    }
    return false;
}
bool bvh_any_hit_passes(int triangle, float u, float v) {
    return shadow_passes(floatBitsToInt(triangles[3 * triangle].w), triangle, u, v);
}
#ifdef GLSLPPM_INSTANCES
bool bvh_any_hit_passes_instanced(int triangle, int instance, float u, float v) {
    int m = floatBitsToInt(triangles[3 * triangle].w) + bvh_instance_bases(instance).w;
    return shadow_passes(m, triangle, u, v);
}
#endif
#endif

const float DISTANT_LIGHT = 3.0e38;

// One light sample seen from p: the unit direction towards it, the distance to the sampled
// point (DISTANT_LIGHT for the sun and the world) and L_e / (p_pick p(wi)). `ng` is the
// surface's normal at p on the side the light must be on (only the constant world's cosine
// sampling reads it). `pick` chooses the emitter, `u` the point or direction on it.
struct LightSample {
    vec3 wi;
    float distance;
    vec3 radiance_over_pdf;
};

#if defined(HAS_POINT_LIGHTS) || defined(HAS_SPOT_LIGHTS)
// Towards a uniform point of the disc of radius r about centre facing `facing` (ls.wi and
// ls.distance; false where it is p itself); d2: the squared distance to it.
bool sample_facing_disc(vec3 p, vec3 centre, vec3 facing, float r, float u1, float u2,
                        inout LightSample ls, out float d2) {
    vec3 t, bt;
    orthonormal_basis(facing, t, bt);
    vec2 o = r * sample_disc(u1, u2);
    vec3 to = centre + o.x * t + o.y * bt - p;
    d2 = dot(to, to);
    if (!(d2 > 0.0)) return false;
    ls.distance = sqrt(d2);
    ls.wi = to / ls.distance;
    return true;
}

// Towards the sphere of squared radius r2 about centre, uniformly over the cone it subtends
// (pdf 1 / (2 pi (1 - cos_max))), where the ray meets it at t = (wi . to) -
// sqrt(r^2 - |to|^2 + (wi . to)^2); false from inside it (it emits outwards).
bool sample_sphere_cone(vec3 p, vec3 centre, float r2, float u1, float u2,
                        inout LightSample ls, out float one_minus_cos) {
    vec3 to = centre - p;
    float d2 = dot(to, to);
    one_minus_cos = 0.0;
    if (!(d2 > r2)) return false;
    float cos_max = sqrt(max(0.0, 1.0 - r2 / d2));
    one_minus_cos = (r2 / d2) / (1.0 + cos_max);  // without cancellation
    ls.wi = sample_cone(to * inversesqrt(d2), cos_max, u1, u2);
    float t_c = dot(ls.wi, to);
    ls.distance = t_c - sqrt(max(0.0, r2 - d2 + t_c * t_c));
    return true;
}
#endif

#ifdef HAS_POINT_LIGHTS
// A point light's sample (the record's a: position, b.w: radius, b.x: Light::facing_disc).
LightSample sample_point_light(vec3 p, vec4 a, vec4 b, vec3 power, float u1, float u2) {
    LightSample ls = LightSample(vec3(0.0, 0.0, 1.0), 0.0, vec3(0.0));
    vec3 to = a.xyz - p;
    float d2 = dot(to, to);
    if (!(d2 > 0.0)) return ls;
    if (b.w <= 0.0) {
        // A point of intensity P / 4 pi: E = I / d^2.
        ls.distance = sqrt(d2);
        ls.wi = to / ls.distance;
        ls.radiance_over_pdf = power / (4.0 * PI * d2);
        return ls;
    }
    if (b.x > 0.5) {
        // Light.facing_disc (Cycles 3.x, and 4.x with Soft Falloff on): the disc of radius r
        // facing p, of the sphere's radiance, sampled uniformly by area: L / pdf =
        // L pi r^2 cos_l / t^2 = P cos_l / (4 pi t^2). Photons keep the sphere.
        vec3 facing = -to * inversesqrt(d2);
        float t2;
        if (sample_facing_disc(p, a.xyz, facing, b.w, u1, u2, ls, t2))
            ls.radiance_over_pdf = power * (max(0.0, dot(facing, -ls.wi)) / (4.0 * PI * t2));
        return ls;
    }
    // A Lambertian sphere of radius r and radiance L = P / (4 pi^2 r^2) (its photons leave
    // a uniform point cosine-weighted), over the cone it subtends.
    float r2 = b.w * b.w, one_minus_cos;
    if (sample_sphere_cone(p, a.xyz, r2, u1, u2, ls, one_minus_cos))
        ls.radiance_over_pdf = power * (2.0 * PI * one_minus_cos / (4.0 * PI * PI * r2));
    return ls;
}
#endif

#ifdef HAS_SPOT_LIGHTS
// A spot light's sample (a: position, b: axis and cos of the half cone, c: smooth edge,
// radius and the code of spot_cosine_falloff / spot_facing_disc): intensity P / 4 pi times
// the smooth edge (and Blender 3.x's cosine towards the axis). The record holds the hard
// cone's power P Omega / 4 pi.
LightSample sample_spot_light(vec3 p, vec4 a, vec4 b, vec4 c, vec3 power, float u1, float u2) {
    LightSample ls = LightSample(vec3(0.0, 0.0, 1.0), 0.0, vec3(0.0));
    float solid_angle = 2.0 * PI * (1.0 - b.w);
    if (!(solid_angle > 0.0)) return ls;
    bool disc = spot_facing_disc(c.z);
    if (!disc && c.y > 0.0) {
        // The sphere of radius r (Cycles 4.x with Soft Falloff off), radiance I / (pi r^2),
        // over the cone it subtends as a point light's (L / pdf = I 2 (1 - cos_max) / r^2),
        // times the cone's edge towards each sampled point. Photons start from the disc.
        float r2 = c.y * c.y, one_minus_cos;
        if (sample_sphere_cone(p, a.xyz, r2, u1, u2, ls, one_minus_cos))
            ls.radiance_over_pdf = power * (spot_attenuation(b.xyz, -ls.wi, b.w, c.x) *
                                            2.0 * one_minus_cos / (solid_angle * r2));
        return ls;
    }
    // A point (radius 0), or Cycles' disc of radius r facing p, of radiance I / (pi r^2),
    // sampled by area: E = I cos_l / d^2 (as a point light's facing disc).
    vec3 from_light = p - a.xyz;
    float l2 = dot(from_light, from_light);
    vec3 facing = l2 > 0.0 ? from_light * inversesqrt(l2) : b.xyz;
    float d2;
    if (!sample_facing_disc(p, a.xyz, facing, c.y, u1, u2, ls, d2)) return ls;
    float attenuation = spot_attenuation(b.xyz, -ls.wi, b.w, c.x);
    if (spot_cosine_falloff(c.z)) attenuation *= max(0.0, dot(b.xyz, -ls.wi));
    if (c.y > 0.0) attenuation *= max(0.0, dot(facing, -ls.wi));
    if (attenuation > 0.0)
        ls.radiance_over_pdf = power * (attenuation / (solid_angle * d2));
    return ls;
}
#endif

// The light sample's pick of an emitter. Photons pick emitters by power (pick_emitter), which
// spreads the world's flux over the scene's whole bounding disc: a dim grey world around a
// lamp can outweigh the lamp (the showcase's 0.022 world took 58% of the light samples from
// its 2 cm spot, whose lit table then read 110% pixel noise a pass). So a light sample splits
// its pick between the world and the other emitters by their irradiance estimated at the
// shading point p: the world's pi mean(L) against the others' power over 4 pi (d^2 + spread^2)
// from their power-weighted centre, plus the suns' irradiance (LightSplit,
// native/render/emitters.cpp). The others keep their power-based pick among themselves. Each
// side keeps at least a tenth of its power-based share, so that where the estimate is wrong
// (the lamp hidden from p) the variance grows at most tenfold. Every density a light sample
// is weighed with reads light_sample_pick at the same p (light_pick_at), so the estimate
// stays unbiased whatever the split; without a world, or with the world alone, the pick is
// the power-based one, bit for bit.
float light_world_share_here = -1.0;  // this point's share of the world; < 0: by power
float light_split_boundary = 1.0;     // the pick numbers below this draw the other emitters

void light_pick_at(vec3 p) {
    light_world_share_here = -1.0;
#ifdef HAS_ENVIRONMENT
    uint k = emitter_count - 1u;
    if (emitter_count < 2u || emitter_kind(k) != EMITTER_ENVIRONMENT) return;
    float boundary = emitter_record(k - 1u, EMITTER_C).w;  // cumulative pick before the world
    if (!(boundary > 0.0 && boundary < 1.0)) return;
    vec3 to = p - light_split_centre.xyz;
    float rest = light_split_power.x / (4.0 * PI * (dot(to, to) + light_split_centre.w)) +
                 light_split_power.y;
    float world = light_split_power.z;
    float by_power = 1.0 - boundary;
    float share = world + rest > 0.0 ? world / (world + rest) : by_power;
    light_world_share_here = clamp(share, 0.1 * by_power, 1.0 - 0.1 * boundary);
    light_split_boundary = boundary;
#endif
}

// The pick number u (uniform in [0, 1)) turned into the one that draws the world with this
// point's share and the other emitters by power below the boundary.
float light_pick_number(float u) {
    float w = light_world_share_here, b = light_split_boundary;
    if (w < 0.0) return u;
    if (u < w) return b + (u / w) * (1.0 - b);
    return min(((u - w) / (1.0 - w)) * b, uintBitsToFloat(floatBitsToUint(b) - 1u));
}

// The probability that this point's light sample picks emitter k.
float light_sample_pick(uint k) {
    float pick = emitter_record(k, EMITTER_POWER).w;
    float w = light_world_share_here;
    if (w < 0.0) return pick;
    return emitter_kind(k) == EMITTER_ENVIRONMENT ? w : pick * ((1.0 - w) / light_split_boundary);
}

LightSample sample_light(vec3 p, vec3 ng, float pick, vec4 u) {
    LightSample ls = LightSample(vec3(0.0, 0.0, 1.0), 0.0, vec3(0.0));
    uint k = pick_emitter(pick);
    vec4 a = emitter_record(k, EMITTER_A);
    vec4 b = emitter_record(k, EMITTER_B);
    vec4 c = emitter_record(k, EMITTER_C);
    vec4 d = emitter_record(k, EMITTER_POWER);
    int kind = floatBitsToInt(a.w) & EMITTER_KIND_MASK;
    float u1 = u.x, u2 = u.y, u3 = u.z, u4 = u.w;
    vec3 power = d.rgb / light_sample_pick(k);  // the emitter's power over its pick probability
#ifdef HAS_TRIANGLE_EMITTERS
    if (kind == EMITTER_TRIANGLE) {
        // Uniform on the triangle (pdf 1 / A) of radiance L = P / (pi A), one-sided about its
        // winding: L cos_l / (d^2 p_pick / A) = (P / p_pick) cos_l / (pi d^2); A cancels.
        // A two-sided (mesh) emitter, b.w = 1, has P = 2 pi L A and |cos_l| on either face.
        vec2 bc = sample_triangle(u1, u2);
        vec3 q = a.xyz + bc.x * (b.xyz - a.xyz) + bc.y * (c.xyz - a.xyz);
        vec3 to = q - p;
        float d2 = dot(to, to);
        if (!(d2 > 0.0)) return ls;
        ls.distance = sqrt(d2);
        ls.wi = to / ls.distance;
        float cos_l = -dot(triangle_normal(a.xyz, b.xyz, c.xyz), ls.wi);
        if (triangle_emitter_two_sided(b.w))
            ls.radiance_over_pdf = power * (abs(cos_l) / (2.0 * PI * d2));
        else if (cos_l > 0.0)
            ls.radiance_over_pdf = power * (cos_l / (PI * d2));
        ls.radiance_over_pdf *= triangle_emitter_texel(b.w, bc);
        return ls;
    }
#endif
#ifdef HAS_POINT_LIGHTS
    if (kind == EMITTER_POINT) return sample_point_light(p, a, b, power, u1, u2);
#endif
#ifdef HAS_SPOT_LIGHTS
    if (kind == EMITTER_SPOT) return sample_spot_light(p, a, b, c, power, u1, u2);
#endif
#ifdef HAS_SUN_LIGHTS
    if (kind == EMITTER_SUN) {
        // Radiance E / Omega over the sun's cone (its photons cross the bounding disc of
        // area pi R^2 uniformly in direction), sampled uniformly: L / pdf = E, and the
        // record holds E pi R^2 / p_pick.
        vec3 travel = b.w < 1.0 ? sample_cone(b.xyz, b.w, u1, u2) : b.xyz;
        ls.wi = -travel;
        ls.distance = DISTANT_LIGHT;
        float disc = PI * scene_radius * scene_radius;
        if (disc > 0.0) ls.radiance_over_pdf = power / disc;
        return ls;
    }
#endif
#ifdef HAS_ENVIRONMENT
    if (kind == EMITTER_ENVIRONMENT) {
        ls.distance = DISTANT_LIGHT;
        float pdf;
#ifdef HAS_ENVIRONMENT_MAP
        // By the map's importance (environment.glsl): L(wi) / (pdf(wi) p_pick).
        ls.wi = sample_environment(u1, u2, u3, u4, pdf);
#else
        // Constant radiance: cosine-weighted about ng, pdf cos / pi.
        ls.wi = sample_cosine_hemisphere(ng, u1, u2);
        pdf = max(0.0, dot(ng, ls.wi)) / PI;
#endif
        if (pdf > 0.0)
            ls.radiance_over_pdf = environment_radiance(ls.wi) / (pdf * light_sample_pick(k));
        return ls;
    }
#endif
    return ls;
}

#ifdef HAS_ENVIRONMENT
// The density per solid angle with which light sampling (below) draws wi from the world:
// its pick probability times the map's density, or the cosine density about `side`, halved
// where the lobe transmits (either side is drawn, with probability 1/2). The world is the
// emitter table's last record (native/render/emitters.cpp) when there is one.
float environment_light_pdf(vec3 wi, vec3 side, bool transmits) {
    uint k = emitter_count - 1u;
    if (emitter_kind(k) != EMITTER_ENVIRONMENT) return 0.0;
    float pick = light_sample_pick(k);
#ifdef HAS_ENVIRONMENT_MAP
    return pick * environment_pdf(wi);
#else
    float c = dot(side, wi);
    if (transmits) return pick * 0.5 * abs(c) / PI;
    return c > 0.0 ? pick * c / PI : 0.0;
#endif
}
#endif

#ifdef HAS_EMITTER_MIS
// Multiple importance sampling of emissive triangles (mesh emission and area lights; Veach
// 1997, section 9.2, the balance heuristic): at a glossy visible point a light sample is
// noisy where the lobe is narrow and the emitter large or near (a small highlight), a BSDF
// sample where the emitter is small. Each estimate weighs its direction by its own density over
// the sum of both, so the two add up to the emitter's whole direct light. Nothing else adds
// it: the eye path ends at this point, photons store no first hit from an emitter
// (DIRECT_LIGHT_SAMPLED), and the BSDF sample adds only emission, never light reflected
// where it lands (docs/direct_light.md, "The whole direct light, once").

// The density per solid angle with which sample_light draws wi from triangle emitter k and
// reaches the point at `distance`: p_pick (1 / A) d^2 / |cos_l| (uniform on the triangle,
// dA = d^2 dw / |cos_l|), as its estimate L_e |cos_l| A / (p_pick d^2) holds it. The light
// sample's weight and the BSDF sample's read this one function, so they sum to one.
float triangle_light_pdf(uint k, vec3 wi, float distance) {
    vec3 a = emitter_record(k, EMITTER_A).xyz;
    vec3 e1 = emitter_record(k, EMITTER_B).xyz - a;
    vec3 e2 = emitter_record(k, EMITTER_C).xyz - a;
    // Scaled by the largest edge component, as triangle_normal is: d^2 / A neither
    // overflows nor underflows at the extremes of scene scale.
    float m = max(max(max(abs(e1.x), abs(e1.y)), max(abs(e1.z), abs(e2.x))),
                  max(abs(e2.y), abs(e2.z)));
    float projected_area = 0.5 * abs(dot(cross(e1 / m, e2 / m), wi));  // A |cos_l| / m^2
    if (!(projected_area > 0.0)) return 0.0;
    float d = distance / m;
    return light_sample_pick(k) * (d * d / projected_area);
}

// What triangle emitter k (packed triangle t) radiates at barycentrics bc towards -wi, as
// sample_light weighs it: its material's emission times its texel, nothing from the back of
// a one-sided emitter.
vec3 triangle_emitter_radiance(uint k, int t, vec2 bc, vec3 wi) {
    vec4 a = emitter_record(k, EMITTER_A), b = emitter_record(k, EMITTER_B);
    vec4 c = emitter_record(k, EMITTER_C);
    if (!triangle_emitter_two_sided(b.w) && dot(triangle_normal(a.xyz, b.xyz, c.xyz), wi) >= 0.0)
        return vec3(0.0);
    return material_emission(floatBitsToInt(triangles[3 * t].w)) * triangle_emitter_texel(b.w, bc);
}

// Issue 30: the BSDF sample costs the GPU a closest-hit walk per pixel and pass (a third to a
// half of its passes/s on mostly Lambertian scenes), and a Lambertian lobe needs it only for
// the rare emitter a light sample by area misses (one a millimetre away). So a Lambertian
// point takes it with probability q (Settings::emitter_mis_fraction) and the two samples are
// combined by the balance heuristic with q BSDF samples to one light sample (Veach 1997,
// 9.2.2, n_light = 1, n_bsdf = q). For a direction wi of densities p_L and p_B:
//   light sample:  f L_e cos / p_L * p_L / (p_L + q p_B)          = f L_e cos / (p_L + q p_B)
//   BSDF sample:   taken / q * f L_e cos / p_B * q p_B / (p_L + q p_B)
//                                                        = taken * f L_e cos / (p_L + q p_B)
// where `taken` is 1 with probability q, drawn independently of wi. The expected sum is
//   int f L_e cos (p_L + q p_B) / (p_L + q p_B) dwi = int f L_e cos dwi
// for any q in (0, 1]: unbiased, and q = 1 is the sample of every pass. Both terms stay below
// f L_e cos / (q p_B), so the variance stays bounded where p_L vanishes (the near spike).
// The draw is made per work group of pixels and pass (emitter_mis_choice), so that a GPU's
// warps skip the ray together: a draw per pixel would leave nearly every warp paying for it.
// Glossy lobes, whose highlights need the sample most, keep q = 1. The world's BSDF sample
// at a Lambertian point shares the ray and so the same q (its light sample's weight too).
// The stage sets these before direct_light_sampled_lobes; their defaults (q = 1, taken) are
// the sample of every pass, which VCM's eye subpaths keep.
float lambertian_emitter_mis_fraction = 1.0;
bool lambertian_emitter_mis_taken = true;

uint emitter_mis_hash(uint v) {  // the PCG hash (Jarzynski and Olano, JCGT 2020)
    v = v * 747796405u + 2891336453u;
    v = ((v >> ((v >> 28u) + 4u)) ^ v) * 277803737u;
    return (v >> 22u) ^ v;
}

// Whether this pass's Lambertian points of the LOCAL_SIZE pixels about `frame_pixel` (its
// index in the whole frame; in a whole frame the block is the work group) take the BSDF
// sample. Each block walks the Weyl sequence phi + k q (mod 1) over the pass index k from a
// phase phi hashed from (the render's seed, the block), and takes the sample in pass k where
// the step from k q + phi to (k + 1) q + phi crosses an integer: with phi uniform that is
// probability q in every pass, as the weights need, while K passes take it floor(K q) or
// ceil(K q) times, where independent draws would spread that count by sqrt(K q (1 - q)): where
// only the BSDF sample finds the light, a block 22% off after 64 passes at q = 1/4. In 32-bit
// fixed point: q = step / 2^32 exactly (the host rounds q so: camera_frame.cpp), the carry
// out of phi + k step + step is the crossing. A pass stays a function of (seed, pass index),
// and a tile or region draws what the whole frame draws.
void emitter_mis_choice(uint frame_pixel) {
    lambertian_emitter_mis_fraction = emitter_mis_fraction;
    if (emitter_mis_fraction >= 1.0) return;  // every pass (2^32 steps do not fit a uint)
    uint step = uint(emitter_mis_fraction * 4294967296.0);
    uint phase = emitter_mis_hash(frame_pixel / LOCAL_SIZE + emitter_mis_hash(render_seed));
    uint at = phase + pass_index * step;  // mod 2^32
    lambertian_emitter_mis_taken = at + step < at;
}

// A BSDF-sampled ray sees the scene as a shadow ray does: through area lights, objects that
// cast no shadow and cut-outs (shadow_passes), adding the emitters it crosses, up to this
// many surfaces.
const int BSDF_RAY_CROSSINGS = 8;

// The light a BSDF sample wi from p meets, each emitter's radiance over p_bsdf + p_light (its
// balance-heuristic weight over p_bsdf; at a Lambertian point p_bsdf is q times the BSDF's
// density, above): the emissive triangles on its way (`triangles_too`:
// at glossy points) and the world where it leaves the scene. `side` and `transmits` as
// environment_light_pdf reads them; `seed` for the cut-outs it crosses.
vec3 light_along_bsdf_sample(vec3 p, vec3 ng, vec3 wi, float p_bsdf, bool triangles_too,
                             vec3 side, bool transmits, uint seed, inout uint rays) {
    vec3 sum = vec3(0.0);
    Ray ray = make_ray(offset_origin(p, ng, wi), wi);
#ifdef BVH_ANY_HIT_FILTER
    shadow_ray_seed = seed;
#endif
    LINK_SHADOW_RAY(LINK_SET_ANY);  // shadow_passes: what passes every emitter's light
#ifdef LIGHT_LINKING
    uint link_shadowed = 0u;  // the sets shadowed by the surfaces crossed so far
#endif
    for (int crossing = 0; crossing < BSDF_RAY_CROSSINGS; ++crossing) {
        ++rays;
        Hit hit = closest_hit(ray);
        if (hit.triangle < 0) {
#ifdef HAS_ENVIRONMENT
            float p_light = environment_light_pdf(wi, side, transmits);
            // The world's link set is 0.
            if (p_light > 0.0 && LINK_REACHES(0u) && LINK_UNSHADOWED(0u)) {
                vec3 term = environment_radiance(wi) / (p_bsdf + p_light);
                sum += term;
                LIGHT_GROUP_PART(WORLD_GROUP_CODE, light_group_bsdf_weight * term);
            }
#endif
            break;
        }
        int t = hit.triangle;
        vec3 a = triangles[3 * t].xyz, b = triangles[3 * t + 1].xyz, c = triangles[3 * t + 2].xyz;
        vec3 q = a + hit.u * (b - a) + hit.v * (c - a);
        int k = triangles_too ? triangle_emitter(t) : -1;
        if (k >= 0 && LINK_REACHES(emitter_link_set(uint(k))) &&
            LINK_UNSHADOWED(emitter_link_set(uint(k)))) {
            // The light sample's distance is from p, whatever the ray crossed on the way.
            float p_light = triangle_light_pdf(uint(k), wi, length(q - p));
            vec3 term = triangle_emitter_radiance(uint(k), t, vec2(hit.u, hit.v), wi) /
                        (p_bsdf + p_light);
            sum += term;
            LIGHT_GROUP_PART(emitter_group_code(uint(k)), light_group_bsdf_weight * term);
        }
#ifdef BVH_ANY_HIT_FILTER
        int m = floatBitsToInt(triangles[3 * t].w);
#ifdef LIGHT_LINKING
        // An opaque surface shadows the sets of its row; the ray goes on while some set
        // is still unshadowed (an ordinary surface's row shadows every set).
        if (!shadow_passes(m, t, hit.u, hit.v))
            link_shadowed |= shadow_link_blocks[material_link_row(m)];
        if (link_shadowed == 0xFFFFFFFFu) break;
#else
        if (!shadow_passes(m, t, hit.u, hit.v)) break;
#endif
        ray = make_ray(offset_origin(q, triangle_normal(a, b, c), wi), wi);
#else
        break;
#endif
    }
    return sum;
}
#endif

#ifdef GLOSSY_LIGHT_SAMPLES
// The followed glossy vertices' side of it (their f, densities and MIS state).
#include "common/glossy_light_samples.glsl"
#endif

// The BSDF sample of direct_light_sampled_lobes (below): one ray for the world and the
// emissive triangles, followed to what it meets (light_along_bsdf_sample).
vec3 direct_light_bsdf_sample(vec3 p, vec3 ng, Shading sh, vec3 wo, bool rough_only,
                              vec3 u_bsdf, bool triangle_mis, float bsdf_fraction,
                              bool transmits, inout uint rays) {
    vec3 ng_wo = dot(ng, wo) >= 0.0 ? ng : -ng;
    vec3 wi, sampled;
#ifdef HAS_EMITTER_MIS
    bool world_too = false;
#ifdef HAS_ENVIRONMENT
    world_too = true;
#endif
    if (!(triangle_mis || world_too) || !bsdf_sample(sh, wo, u_bsdf, false, wi, sampled))
        return vec3(0.0);
    float p_bsdf = bsdf_pdf(sh, wo, wi);
    vec3 f_rough = bsdf_f(sh, wo, wi, rough_only, false);
#ifdef HAS_NORMAL_MAP
    f_rough *= shading_cosine_ratio(wi, sh.n, ng);
#endif
    if (!(p_bsdf > 0.0) || !any(greaterThan(f_rough, vec3(0.0)))) return vec3(0.0);
    uint seed = floatBitsToUint(u_bsdf.x) ^ (floatBitsToUint(u_bsdf.y) * 0x85EBCA6Bu);
#ifdef LIGHT_GROUPS
    light_group_bsdf_weight = f_rough * abs(dot(ng, wi));
#endif
    return f_rough * abs(dot(ng, wi)) *
           light_along_bsdf_sample(p, ng, wi, bsdf_fraction * p_bsdf, triangle_mis, ng_wo,
                                   transmits, seed, rays);
#elif defined(HAS_ENVIRONMENT)
    if (!bsdf_sample(sh, wo, u_bsdf, false, wi, sampled)) return vec3(0.0);
    float p_bsdf = bsdf_pdf(sh, wo, wi);
    float p_light = environment_light_pdf(wi, ng_wo, transmits);
    vec3 f_rough = bsdf_f(sh, wo, wi, rough_only, false);
    if (!(p_bsdf > 0.0 && p_light > 0.0 && any(greaterThan(f_rough, vec3(0.0))) &&
          LINK_REACHES(0u)))
        return vec3(0.0);
    Ray escape = make_ray(offset_origin(p, ng, wi), wi);
    LINK_SHADOW_RAY(0u);  // the world's
    ++rays;
#ifdef BVH_ANY_HIT_FILTER
    shadow_ray_seed = floatBitsToUint(u_bsdf.x) ^ (floatBitsToUint(u_bsdf.y) * 0x85EBCA6Bu);
#endif
#ifdef HAS_NORMAL_MAP
    f_rough *= shading_cosine_ratio(wi, sh.n, ng);
#endif
    if (any_hit(escape)) return vec3(0.0);
    vec3 part = f_rough * environment_radiance(wi) * (abs(dot(ng, wi)) / (p_bsdf + p_light));
    LIGHT_GROUP_PART(WORLD_GROUP_CODE, part);
    return part;
#else
    return vec3(0.0);
#endif
}

// The same for a material of common/lobes.glsl, whose lobes may transmit: the light may be on
// either side. `rough_only`: the smooth lobes, followed by the eye path, are left out.
// Glossy lobes see the world better through their own samples than through the world's:
// with an environment, one BSDF sample `u_bsdf` also looks for it, and the two estimates of
// the world's light are combined by the balance heuristic (Veach's multiple importance
// sampling). With HAS_EMITTER_MIS the same BSDF sample looks for emissive triangles too at
// Lambertian and glossy lobes, weighed against light samples of them alike. Other emitters (point, spot
// and sun lights: delta lights no BSDF sample can hit) come from their light samples alone.
// `material`: the point's own (a Mix's root), whose light link row counts.
// `followed` > 0: a glossy vertex the eye path follows with that probability
// (common/glossy_light_samples.glsl): the followed lobe's light sample alone, weighed
// against the continuation. One function for both, so that the eye stage's loop holds one
// copy of the light sample and its shadow ray (two made the glossy Cornell box's passes
// 1.9x slower on an H100).
vec3 direct_light_sampled_lobes(int material, vec3 p, vec3 ng, Shading sh, vec3 wo,
                                bool rough_only, float pick, vec4 u, vec3 u_bsdf,
                                float followed, inout uint rays) {
    vec3 ng_wo = dot(ng, wo) >= 0.0 ? ng : -ng;
    bool transmits = sh.kind == MATERIAL_TRANSLUCENT || sh.kind == MATERIAL_DIELECTRIC;
    // A transmitting lobe sees the constant world from below as well: the cosine-sampled
    // half is chosen by u.w (which that sampler does not read), at half the density.
    vec3 side = transmits && u.w < 0.5 ? -ng_wo : ng_wo;
    light_pick_at(p);
    pick = light_pick_number(pick);
    LightSample ls = sample_light(p, side, pick, u);
    uint picked = pick_emitter(pick);  // the emitter sample_light drew from
    LINK_LIGHT_SAMPLE(material, picked, ls);
    bool world = emitter_kind(picked) == EMITTER_ENVIRONMENT;
#ifdef HAS_EMITTER_MIS
    // Emissive triangles meet BSDF samples at Lambertian and glossy lobes: a light sample drawn by
    // area misses the spike cos cos' / d^2 of a triangle a millimetre away, which a cosine-sampled
    // ray finds at once (issue 30, docs/cornell_vs_cycles.md). A translucent point, and a plastic
    // whose coat the eye path follows (rough_only), keep light samples alone.
    bool triangle_mis = !rough_only && (sh.kind == MATERIAL_DIFFUSE ||
                                        sh.kind == MATERIAL_CONDUCTOR ||
                                        sh.kind == MATERIAL_DIELECTRIC ||
                                        sh.kind == MATERIAL_PLASTIC);
    bool picked_triangle = emitter_kind(picked) == EMITTER_TRIANGLE;
    // Issue 30: a Lambertian point takes the BSDF sample with probability q (above); p_bsdf
    // counts q times in both weights, the world's included, as the sample looks for both.
    bool lambertian = sh.kind == MATERIAL_DIFFUSE;
    float bsdf_fraction = lambertian ? lambertian_emitter_mis_fraction : 1.0;
    bool bsdf_taken = !lambertian || lambertian_emitter_mis_taken;
#else
    bool triangle_mis = false, bsdf_taken = true;
    float bsdf_fraction = 1.0;  // the world's BSDF sample below is taken every pass
#endif
#if defined(HAS_ENVIRONMENT) && !defined(HAS_ENVIRONMENT_MAP)
    if (transmits && world) ls.radiance_over_pdf *= 2.0;
#endif
    float cos_theta = abs(dot(ng, ls.wi));
    vec3 f = bsdf_f(sh, wo, ls.wi, rough_only, false);
#ifdef HAS_NORMAL_MAP
    // A normal map's tilt shades by the shading normal's cosine (the photons' deposits are
    // scaled to match: photon_trace.comp); elsewhere the true surface's, as the photons have it.
    f *= shading_cosine_ratio(ls.wi, sh.n, ng);
#endif
#ifdef GLOSSY_LIGHT_SAMPLES
    float p_followed = 0.0;
    if (followed > 0.0) {
        p_followed = glossy_followed_f_pdf(sh, wo, ls.wi, followed, f);
        cos_theta = abs(dot(sh.n, ls.wi)) / followed;
        glossy_mis_at(ng_wo, transmits);
    }
#endif
    vec3 result = vec3(0.0);
    if (cos_theta > 0.0 && ls.distance > 0.0 && any(greaterThan(ls.radiance_over_pdf, vec3(0.0))) &&
        any(greaterThan(f, vec3(0.0)))) {
        Ray shadow = make_ray(offset_origin(p, ng, ls.wi), ls.wi);
        if (ls.distance < DISTANT_LIGHT) shadow.tmax = ls.distance * (1.0 - 1e-4);
        ++rays;
#ifdef BVH_ANY_HIT_FILTER
        shadow_ray_seed = floatBitsToUint(u.x) ^ (floatBitsToUint(u.y) * 0x85EBCA6Bu);
#endif
        if (!any_hit(shadow)) {
            float weight = 1.0;
#ifdef HAS_ENVIRONMENT
            if (world) {
                float p_light = environment_light_pdf(ls.wi, ng_wo, transmits);
                float p_bsdf = bsdf_fraction * bsdf_pdf(sh, wo, ls.wi);
                weight = p_light / (p_light + p_bsdf);
            }
#endif
#ifdef HAS_EMITTER_MIS
            if (triangle_mis && picked_triangle) {
                float p_light = triangle_light_pdf(picked, ls.wi, ls.distance);
                weight = p_light / (p_light + bsdf_fraction * bsdf_pdf(sh, wo, ls.wi));
            }
#endif
#ifdef GLOSSY_LIGHT_SAMPLES
            if (followed > 0.0) weight = glossy_light_weight(picked, p, ls, p_followed);
#endif
            result = f * ls.radiance_over_pdf * (cos_theta * weight);
            LIGHT_GROUP_PART(emitter_group_code(picked), result);
        }
    }
#ifdef GLOSSY_LIGHT_SAMPLES
    if (followed > 0.0) return result;
#endif
    if (!bsdf_taken) return result;
    return result + direct_light_bsdf_sample(p, ng, sh, wo, rough_only, u_bsdf, triangle_mis,
                                             bsdf_fraction, transmits, rays);
}
#endif
