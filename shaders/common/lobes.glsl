// The material model's lobes: Lambert, GGX conductor (a mirror at roughness 0), GGX rough
// dielectric (smooth glass at roughness 0), a dielectric layer over Lambert ("plastic"),
// translucent and transparent, chosen between by Mix materials. Each lobe has f (bsdf_f), its sampling density (bsdf_pdf) and a sampler
// (bsdf_sample) whose weight is f cos / pdf; every stage evaluates materials here.
//
// Directions point away from the surface. A Shading's frame has its z axis on the side wo
// leaves from (surfaces are two-sided); a dielectric knows from `entering` which side of it
// is the inside. Refraction follows Cycles' convention, so that an image matches Cycles'
// where a dielectric is not a closed solid (a window of one plane, a camera inside water):
// eye paths carry no factor for the change of solid angle, and photons are sampled with that
// kernel's adjoint, which divides by the squared ratio of the indices (eta^2) going into the
// denser medium (Veach's thesis, section 5.2, with the roles of the two transport modes
// exchanged). Through a closed solid the factors cancel, so both conventions agree there.
#ifndef LOBES_GLSL
#define LOBES_GLSL

#include "common/bsdf.glsl"
#include "common/sampling.glsl"
#include "common/bounces.glsl"

float material_roughness(int m) { return material_record(m, MATERIAL_TEXTURES).z; }
int material_roughness_texture(int m) { return floatBitsToInt(material_record(m, MATERIAL_TEXTURES).w); }
ivec2 material_mix(int m) { return floatBitsToInt(material_record(m, MATERIAL_MIX_RECORD).xy); }
float material_mix_factor(int m) { return material_record(m, MATERIAL_MIX_RECORD).z; }
int material_mix_texture(int m) { return floatBitsToInt(material_record(m, MATERIAL_MIX_RECORD).w); }
uint material_options(int m) { return floatBitsToUint(material_record(m, MATERIAL_OPTIONS).x); }
float material_mix_ior(int m) { return material_record(m, MATERIAL_OPTIONS).y; }
int material_table(int m) { return floatBitsToInt(material_record(m, MATERIAL_OPTIONS).z); }

// Albedo tables (native/render/microfacet_tables.h), in the materials buffer after the
// materials: ALBEDO_TABLE_SIZE^2 values E(mu, roughness) on grids uniform in sqrt(mu) and
// roughness over [0, 1] (sqrt(mu) fastest),
// then ALBEDO_TABLE_SIZE hemispherical averages 2 int E(mu) mu dmu; a dielectric has a second
// block for light inside it.
const int ALBEDO_TABLE_VEC4S = (ALBEDO_TABLE_SIZE * ALBEDO_TABLE_SIZE + ALBEDO_TABLE_SIZE) / 4;

float table_entry(int base, int k) { return materials[base + (k >> 2)][k & 3]; }

float albedo_table(int base, float mu, float roughness) {
    const int n = ALBEDO_TABLE_SIZE;
    vec2 x = vec2(sqrt(clamp(mu, 0.0, 1.0)), clamp(roughness, 0.0, 1.0)) * float(n - 1);
    ivec2 i = min(ivec2(x), ivec2(n - 2));
    vec2 f = x - vec2(i);
    int k = i.y * n + i.x;
    float a = mix(table_entry(base, k), table_entry(base, k + 1), f.x);
    float b = mix(table_entry(base, k + n), table_entry(base, k + n + 1), f.x);
    return mix(a, b, f.y);
}

float albedo_average(int base, float roughness) {
    const int n = ALBEDO_TABLE_SIZE;
    float x = clamp(roughness, 0.0, 1.0) * float(n - 1);
    int i = min(int(x), n - 2);
    return mix(table_entry(base, n * n + i), table_entry(base, n * n + i + 1), x - float(i));
}

float texture_channel(vec4 texel, uint channel) {
    return channel == TEXTURE_CHANNEL_LUMINANCE ? luminance(texel.rgb)
                                                : texel[min(channel, TEXTURE_CHANNEL_ALPHA)];
}

// A scalar input: its value times its texture's channel where it has one.
float material_scalar(float value, int texture, uint channel, TexturePoint at) {
#ifdef HAS_TEXTURES
    if (texture >= 0) return value * texture_channel(sample_texture(texture, at), channel);
#endif
    return value;
}

// A Mix material's factor: the probability of its second material. `c` is the cosine between
// the view direction and the shading normal on its side, `front` whether the view is on the
// geometric front (Blender's Fresnel and Layer Weight nodes read both).
float mix_factor(int m, TexturePoint at, float c, bool front) {
    uint options = material_options(m);
    uint mode = (options >> OPTION_MIX_MODE_SHIFT) & 3u;
    float f;
    if (mode == MIX_FACTOR_CONSTANT) {
        f = material_scalar(material_mix_factor(m), material_mix_texture(m),
                            (options >> OPTION_MIX_CHANNEL_SHIFT) & 7u, at);
    } else if (mode == MIX_FACTOR_FRESNEL || mode == MIX_FACTOR_LAYER_FRESNEL) {
        // Blender's Fresnel node inverts the index on back faces; a BSDF's own layer
        // (Principled's specular and coat) reflects as from the front on both sides, as Cycles
        // sets it up. Inverted there, a closed mesh's inside reflected totally beyond 42
        // degrees: Principled v1's doubled specular took photons inside emissive letters to
        // an albedo near 1.8, a furnace whose few escaping photons made the text 1.09x to
        // 1.50x Cycles (tests/python/test_layer_fresnel.py).
        float ior = material_mix_ior(m), cos_t;
        bool as_front = front || mode == MIX_FACTOR_LAYER_FRESNEL;
        f = fresnel_dielectric(c, as_front ? 1.0 / ior : ior, cos_t);
    } else {
        // Layer Weight's Facing: 1 - c^b, the blend b mapped as Blender maps it.
        float blend = min(material_mix_ior(m), 1.0 - 1.0e-5);
        float b = blend < 0.5 ? 2.0 * blend : 0.5 / (1.0 - blend);
        f = 1.0 - pow(c, b);
    }
    return clamp(f, 0.0, 1.0);
}

// Walks from a triangle's material down its Mix materials to one leaf: each mix picks its
// second material with probability equal to its factor (mix_factor), reusing the rest of `u`.
int resolve_mix(int m, TexturePoint at, float c, bool front, float u) {
#ifndef HAS_ROUGH_LOBES
    // A mix makes a scene need the rough lobes (needs_rough_lobes): without them there is
    // none to resolve, and the loop's code left the photon stage 15% slower on the H100.
    return m;
#endif
    for (int level = 0; level < MAX_MIX_DEPTH && material_kind(m) == MATERIAL_MIX; ++level) {
        float f = mix_factor(m, at, c, front);
        ivec2 ab = material_mix(m);
        if (u < f) {
            m = ab.y;
            u = u / f;
        } else {
            m = ab.x;
            u = (u - f) / max(1.0 - f, 1.0e-7);
        }
        u = min(u, 0.99999994);
    }
    return m;
}

float max_component(vec3 c) { return max(c.r, max(c.g, c.b)); }

// How much a material scatters, roughly, for choosing between a mix's parts by what they
// return: a leaf's colour (at least 0.1 for lobes whose Fresnel reflection is white), a mix's
// parts one level down by its factor, deeper ones as 1. Nothing for a black leaf.
float leaf_scatter_estimate(int m) {
    int kind = material_kind(m);
    float c = max_component(material_color(m));
    if (kind == MATERIAL_DIELECTRIC || kind == MATERIAL_PLASTIC ||
        (kind == MATERIAL_CONDUCTOR && (material_options(m) & OPTION_SCHLICK) != 0u))
        return max(c, 0.1);
    return kind == MATERIAL_MIX ? 1.0 : max(c, 0.0);
}

float scatter_estimate(int m, TexturePoint at, float c, bool front) {
    if (material_kind(m) != MATERIAL_MIX) return leaf_scatter_estimate(m);
    float f = mix_factor(m, at, c, front);
    ivec2 ab = material_mix(m);
    return (1.0 - f) * leaf_scatter_estimate(ab.x) + f * leaf_scatter_estimate(ab.y);
}

// resolve_mix for a photon's scattering: each mix picks a part with probability proportional
// to its factor times its scatter_estimate, and `weight` gains the factor over that
// probability. The expected scattering is the material's, but a part mixed in with weight
// doubled (Add Shader, Principled v1's specular over black) no longer doubles a photon's flux
// half of the time: its flux stays near the albedo's, where heavy tails made fireflies that
// never averaged out (a closed emissive Principled mesh, whose light bounces inside).
int resolve_mix_by_scatter(int m, TexturePoint at, float c, bool front, float u,
                           out float weight) {
    weight = 1.0;
    for (int level = 0; level < MAX_MIX_DEPTH && material_kind(m) == MATERIAL_MIX; ++level) {
        float f = mix_factor(m, at, c, front);
        ivec2 ab = material_mix(m);
        float ea = (1.0 - f) * scatter_estimate(ab.x, at, c, front);
        float eb = f * scatter_estimate(ab.y, at, c, front);
        float pb = ea + eb > 0.0 ? eb / (ea + eb) : f;
        // A part with a non-zero factor keeps its factor's chance where the other's estimate
        // takes all: Principled v1's Fresnel mix of black and a doubled specular then picks
        // black (1 - F) as before. Without this the weights stay at the albedo; the text
        // under 3.4 measured 1.77x Cycles against 1.37x with it while the layer's Fresnel
        // reflected totally inside closed meshes (mix_factor), and the same since (1.0174x
        // against 1.0179x at 128 passes).
        if (f > 0.0 && pb <= 0.0) pb = f;
        if (f < 1.0 && pb >= 1.0) pb = f;
        if (u < pb) {
            m = ab.y;
            weight *= f / pb;
            u = u / pb;
        } else {
            m = ab.x;
            weight *= (1.0 - f) / (1.0 - pb);
            u = (u - pb) / max(1.0 - pb, 1.0e-7);
        }
        u = min(u, 0.99999994);
    }
    return m;
}

struct Shading {
    int material;     // the leaf, after mixes
    int kind;
    vec3 color;       // textured
    float roughness;  // textured
    float alpha;      // GGX alpha
    float ior;
    int table;        // albedo table (vec4 index), -1 for none
    uint options;
    bool entering;    // wo on the geometric front: a dielectric's outside
    vec3 t, b, n;     // frame; n is the shading normal on wo's side
#ifdef HAS_F82_TINT
    vec3 f82;         // Schlick conductor: the F82 tint's term b (conductor_fresnel)
#endif
#ifdef HAS_NORMAL_MAP
    vec3 ng;          // the geometric normal on wo's side (bump_shadowing)
#endif
};

// A leaf material with its frame: n is the shading normal on wo's side.
Shading shading_of_leaf(int m, vec3 n, TexturePoint at, vec3 vertex_color, bool entering) {
    Shading sh;
    sh.entering = entering;
    sh.n = n;
    orthonormal_basis(sh.n, sh.t, sh.b);
#ifdef HAS_NORMAL_MAP
    sh.ng = n;  // shading_at and the gather set the true one
#endif
    sh.material = m;
    sh.kind = material_kind(m);
    sh.options = material_options(m);
    sh.color = material_color_at(m, at, vertex_color);
#ifdef HAS_ROUGH_LOBES
    sh.roughness = clamp(material_scalar(material_roughness(m), material_roughness_texture(m),
                                         sh.options & OPTION_ROUGHNESS_CHANNEL, at), 0.0, 1.0);
    sh.alpha = ggx_alpha(sh.roughness);
    sh.ior = material_ior(m);
    sh.table = material_table(m);
#else
    // Lambert, the mirror and smooth glass: roughness 0 and no albedo table
    // (needs_rough_lobes), without reading the record's roughness and texture fields.
    sh.roughness = 0.0;
    sh.alpha = 0.0;
    sh.ior = material_ior(m);
    sh.table = -1;
#endif
#ifdef HAS_F82_TINT
    // Blender 4.x's F82 tint (Cycles' fresnel_f82tint): F = Schlick - b mu (1 - mu)^6 with b
    // chosen so that F at mu = 1/7 (about 82 degrees) is Schlick's there times the tint:
    // b = Schlick(1/7) 7 / (6/7)^6 (1 - tint). White tint: b = 0, Schlick unchanged.
    vec3 tint = material_record(m, MATERIAL_EMISSION_TEXTURE).yzw;
    const float f = 6.0 / 7.0;
    float f5 = f * f * f * f * f;
    sh.f82 = mix(sh.color, vec3(1.0), f5) * (7.0 / (f5 * f)) * (1.0 - tint);
#endif
    return sh;
}

#ifdef HAS_NORMAL_MAP
// A normal map may tilt the shading normal so far that wo's mirror direction points under
// the surface: black fringes and light leaking through. As Cycles does (its
// ensure_valid_specular_reflection), the normal is bent towards the geometric one, in their
// common plane, just until that mirror direction leaves `lift` = min(0.9 cos_o, 0.01) above
// the surface. With n = x sin(theta) + ng cos(theta), x the unit direction of n's tangential
// part, the mirror direction's height is wo.ng cos(2 theta) + wo.x sin(2 theta)
// = rho cos(2 theta - psi): 2 theta is moved to the nearer edge of the cone
// |2 theta - psi| <= acos(lift / rho). ng is on wo's side.
vec3 valid_shading_normal(vec3 n, vec3 ng, vec3 wo) {
    float iz = dot(wo, ng);
    float lift = min(0.9 * iz, 0.01);
    if (dot(2.0 * dot(n, wo) * n - wo, ng) >= lift) return n;
    vec3 x = n - dot(n, ng) * ng;
    float lx = length(x);
    if (lx < 1.0e-7 || iz <= 0.0) return ng;
    x /= lx;
    float ix = dot(wo, x);
    float rho = length(vec2(ix, iz));
    float psi = atan(ix, iz);
    float cone = acos(clamp(lift / rho, -1.0, 1.0));
    float two_theta = 2.0 * atan(lx, dot(n, ng));
    two_theta = two_theta > psi ? psi + cone : psi - cone;
    float theta = clamp(0.5 * two_theta, 0.0, 0.5 * PI);
    return sin(theta) * x + cos(theta) * ng;
}
#endif

#ifdef HAS_NORMAL_MAP
// |w.ns| / |w.ng|: what turns light counted per area of the true surface (photons, a light
// sample's geometric cosine) into the shading normal's cosine (Veach's thesis, 5.3).
float shading_cosine_ratio(vec3 w, vec3 ns, vec3 ng) {
    return abs(dot(w, ns)) / max(abs(dot(w, ng)), 1.0e-6);
}
#endif

// The material at a surface seen from wo; `u` picks between mixes.
Shading shading_at(int material, vec3 n, vec3 ng, TexturePoint at, vec3 vertex_color, vec3 wo,
                   float u) {
    bool entering = dot(wo, ng) >= 0.0;
    vec3 n_wo = entering ? n : -n;
#ifdef HAS_NORMAL_MAP
    n_wo = valid_shading_normal(n_wo, entering ? ng : -ng, wo);
#endif
    int leaf = resolve_mix(material, at, clamp(dot(wo, n_wo), 0.0, 1.0), entering, u);
    Shading sh = shading_of_leaf(leaf, n_wo, at, vertex_color, entering);
#ifdef HAS_NORMAL_MAP
    sh.ng = entering ? ng : -ng;
#endif
    return sh;
}

// shading_at for a photon's scattering: the leaf chosen by resolve_mix_by_scatter, whose
// `weight` multiplies the sample's.
Shading shading_at_by_scatter(int material, vec3 n, vec3 ng, TexturePoint at, vec3 vertex_color, vec3 wo,
                              float u, out float weight) {
    bool entering = dot(wo, ng) >= 0.0;
    vec3 n_wo = entering ? n : -n;
#ifdef HAS_NORMAL_MAP
    n_wo = valid_shading_normal(n_wo, entering ? ng : -ng, wo);
#endif
    int leaf = resolve_mix_by_scatter(material, at, clamp(dot(wo, n_wo), 0.0, 1.0), entering, u,
                                      weight);
    Shading sh = shading_of_leaf(leaf, n_wo, at, vertex_color, entering);
#ifdef HAS_NORMAL_MAP
    sh.ng = entering ? ng : -ng;
#endif
    return sh;
}

vec3 to_local(Shading sh, vec3 v) { return vec3(dot(v, sh.t), dot(v, sh.b), dot(v, sh.n)); }
vec3 to_world(Shading sh, vec3 v) { return v.x * sh.t + v.y * sh.b + v.z * sh.n; }


// ---- Conductor: GGX with Fresnel = the colour (Glossy) or Schlick from it (Principled's
// metal), plus Kulla and Conty's multiple-scattering lobe where compensation is on:
//   f_ms = F_ms (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - E_avg)),
// which restores a white conductor's albedo to 1 and is reciprocal.

vec3 conductor_fresnel(Shading sh, float c) {
    if ((sh.options & OPTION_SCHLICK) == 0u) return sh.color;
#ifdef HAS_F82_TINT
    float k = 1.0 - clamp(c, 0.0, 1.0);
    float k3 = k * k * k;
    return max(fresnel_schlick(sh.color, c) - sh.f82 * (c * k3 * k3), vec3(0.0));
#else
    return fresnel_schlick(sh.color, c);
#endif
}

float conductor_multiple_probability(Shading sh, vec3 wo) {
    if ((sh.options & OPTION_MULTISCATTER) == 0u) return 0.0;
    return 1.0 - albedo_table(sh.table, wo.z, sh.roughness);
}

vec3 conductor_f(Shading sh, vec3 wo, vec3 wi) {
    if (wo.z <= 0.0 || wi.z <= 0.0) return vec3(0.0);
    float a2 = sh.alpha * sh.alpha;
    vec3 h = normalize(wo + wi);
    vec3 f = conductor_fresnel(sh, dot(wo, h)) * (ggx_d(h, a2) * ggx_g2(wo.z, wi.z, a2) /
                                                  (4.0 * wo.z * wi.z));
    if ((sh.options & OPTION_MULTISCATTER) != 0u) {
        float e_o = albedo_table(sh.table, wo.z, sh.roughness);
        float e_i = albedo_table(sh.table, wi.z, sh.roughness);
        float e_avg = albedo_average(sh.table, sh.roughness);
#ifdef HAS_F82_TINT
        // With the F82 term: its hemispherical average 2 int mu^2 (1 - mu)^6 = 1 / 126.
        vec3 f_avg = (sh.options & OPTION_SCHLICK) != 0u
                         ? max(fresnel_schlick_average(sh.color) - sh.f82 / 126.0, vec3(0.0))
                         : sh.color;
#else
        vec3 f_avg = (sh.options & OPTION_SCHLICK) != 0u ? fresnel_schlick_average(sh.color)
                                                         : sh.color;
#endif
        vec3 f_ms = f_avg * f_avg * e_avg / (1.0 - f_avg * (1.0 - e_avg));
        f += f_ms * ((1.0 - e_o) * (1.0 - e_i) / (PI * max(1.0 - e_avg, 1.0e-6)));
    }
    return f;
}

float conductor_pdf(Shading sh, vec3 wo, vec3 wi) {
    if (wo.z <= 0.0 || wi.z <= 0.0) return 0.0;
    float p_ms = conductor_multiple_probability(sh, wo);
    vec3 h = normalize(wo + wi);
    float a2 = sh.alpha * sh.alpha;
    return (1.0 - p_ms) * ggx_reflection_pdf(wo, h, a2) + p_ms * wi.z / PI;
}

bool conductor_sample(Shading sh, vec3 wo, vec3 u, out vec3 wi) {
    if (wo.z <= 0.0) return false;
    if (u.z < conductor_multiple_probability(sh, wo)) {
        float r = sqrt(u.x), phi = 2.0 * PI * u.y;
        wi = vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u.x)));
    } else {
        vec3 h = ggx_sample_visible(wo, sh.alpha, u.x, u.y);
        wi = 2.0 * dot(wo, h) * h - wo;
    }
    return wi.z > 0.0;
}

// ---- Rough dielectric (Walter et al. 2007), reflection and refraction chosen by Fresnel at
// the sampled normal. etap = n(wi side) / n(wo side) for refraction. With compensation on,
// f is divided by the lobe's albedo at wo (albedo scaling: energy-conserving, not reciprocal).

float dielectric_eta(Shading sh) { return sh.entering ? sh.ior : 1.0 / sh.ior; }

float dielectric_albedo(Shading sh, vec3 wo) {
    if ((sh.options & OPTION_MULTISCATTER) == 0u || sh.table < 0) return 1.0;
    return max(albedo_table(sh.table + (sh.entering ? 0 : ALBEDO_TABLE_VEC4S), wo.z,
                            sh.roughness), 0.05);
}

// The generalised half vector of wo and wi and whether it is a valid configuration.
bool dielectric_half(Shading sh, vec3 wo, vec3 wi, out vec3 m, out float etap) {
    bool reflection = wi.z > 0.0;
    etap = reflection ? 1.0 : dielectric_eta(sh);
    m = wi * etap + wo;
    if (wi.z == 0.0 || dot(m, m) == 0.0) return false;
    m = normalize(m);
    if (m.z < 0.0) m = -m;
    // Microfacets seen from behind reflect or refract nothing.
    return dot(m, wi) * wi.z > 0.0 && dot(m, wo) * wo.z > 0.0;
}

vec3 dielectric_f(Shading sh, vec3 wo, vec3 wi, bool adjoint) {
    vec3 m;
    float etap;
    if (wo.z <= 0.0 || !dielectric_half(sh, wo, wi, m, etap)) return vec3(0.0);
    float a2 = sh.alpha * sh.alpha;
    float cos_t;
    float F = fresnel_dielectric(dot(wo, m), 1.0 / dielectric_eta(sh), cos_t);
    float dg = ggx_d(m, a2) * ggx_g2(wo.z, abs(wi.z), a2);
    vec3 tint = (sh.options & OPTION_TINT_REFLECTION) != 0u ? sh.color : vec3(1.0);
    vec3 f;
    if (wi.z > 0.0) {
        f = tint * (F * dg / (4.0 * wo.z * wi.z));
    } else {
        float denom = dot(wi, m) + dot(wo, m) / etap;
        f = sh.color * ((1.0 - F) * dg * abs(dot(wi, m) * dot(wo, m)) /
                        (abs(wi.z) * wo.z * denom * denom));
        if (adjoint) f /= etap * etap;  // photons: see the top of this file
    }
    return f / dielectric_albedo(sh, wo);
}

float dielectric_pdf(Shading sh, vec3 wo, vec3 wi) {
    vec3 m;
    float etap;
    if (wo.z <= 0.0 || !dielectric_half(sh, wo, wi, m, etap)) return 0.0;
    float a2 = sh.alpha * sh.alpha;
    float cos_t;
    float F = fresnel_dielectric(dot(wo, m), 1.0 / dielectric_eta(sh), cos_t);
    float visible = ggx_visible_pdf(wo, m, a2);
    if (wi.z > 0.0) return F * visible / (4.0 * dot(wo, m));
    float denom = dot(wi, m) + dot(wo, m) / etap;
    return (1.0 - F) * visible * abs(dot(wi, m)) / (denom * denom);
}

bool dielectric_sample(Shading sh, vec3 wo, vec3 u, out vec3 wi) {
    if (wo.z <= 0.0) return false;
    vec3 m = ggx_sample_visible(wo, sh.alpha, u.x, u.y);
    float c = dot(wo, m);
    if (c <= 0.0) return false;
    float eta = 1.0 / dielectric_eta(sh);  // n(wo side) / n(other side)
    float cos_t;
    float F = fresnel_dielectric(c, eta, cos_t);
    if (u.z < F) {
        wi = 2.0 * c * m - wo;
        return wi.z > 0.0;
    }
    wi = eta * -wo + (eta * c - cos_t) * m;
    return wi.z < 0.0;
}

// ---- Plastic: a GGX dielectric layer (white, index ior) over a Lambert base. The base is
// scaled by what the layer lets through, reciprocally, with the layer's albedo Es:
//   f_d = colour (1 - Es(mu_o)) (1 - Es(mu_i)) / (pi (1 - Es_avg)),
// so a white base reflects exactly 1 in total.

float plastic_layer_albedo(Shading sh, float mu) { return albedo_table(sh.table, mu, sh.roughness); }

// How often the sampler picks the layer: its albedo against what the base returns.
float plastic_layer_probability(Shading sh, vec3 wo) {
    float es = plastic_layer_albedo(sh, wo.z);
    float rest = (1.0 - es) * max_component(sh.color);
    return es + rest > 0.0 ? es / (es + rest) : 1.0;
}

vec3 plastic_layer_f(Shading sh, vec3 wo, vec3 wi) {
    if (wo.z <= 0.0 || wi.z <= 0.0) return vec3(0.0);
    float a2 = sh.alpha * sh.alpha;
    vec3 h = normalize(wo + wi);
    float cos_t;
    float F = fresnel_dielectric(dot(wo, h), 1.0 / sh.ior, cos_t);
    return vec3(F * ggx_d(h, a2) * ggx_g2(wo.z, wi.z, a2) / (4.0 * wo.z * wi.z));
}

vec3 plastic_base_f(Shading sh, vec3 wo, vec3 wi) {
    if (wo.z <= 0.0 || wi.z <= 0.0) return vec3(0.0);
    float es_avg = albedo_average(sh.table, sh.roughness);
    return sh.color * ((1.0 - plastic_layer_albedo(sh, wo.z)) *
                       (1.0 - plastic_layer_albedo(sh, wi.z)) / (PI * max(1.0 - es_avg, 1.0e-6)));
}

float plastic_layer_pdf(Shading sh, vec3 wo, vec3 wi) {
    vec3 h = normalize(wo + wi);
    float a2 = sh.alpha * sh.alpha;
    return ggx_reflection_pdf(wo, h, a2);
}

// ---- The material: dispatch on the leaf's kind. Only scenes with a lobe beyond Lambert, the
// mirror and smooth glass (a roughness, a layer, a mix, translucency, a cut-out) compile the
// others' cases (HAS_ROUGH_LOBES): llvmpipe runs every case of a switch, masked per lane, and
// those cases cost a Lambert-only scene a third of its pass there (see docs/materials.md). A lobe is smooth when its roughness is
// below the threshold (Frame's glossy_threshold) or 0 (a mirror, whatever the threshold: its
// f is a delta no visible point can evaluate): eye paths then follow it by sampling,
// and visible points hold only the rough lobes ("rough_only"). Rough dielectrics are
// followed at every roughness, as pbrt-v4's SPPM follows glossy lobes: a visible point on
// frosted glass gathers photons through a narrow transmission lobe, whose estimate is far
// noisier than that of the surfaces seen through it.

bool lobe_smooth(Shading sh) {
    return sh.kind == MATERIAL_DIELECTRIC || sh.roughness < glossy_threshold || sh.roughness == 0.0;
}

// Whether photons landing here can be gathered: the material has a lobe that visible points
// evaluate.
bool bsdf_has_rough_lobe(Shading sh) {
    if (sh.kind == MATERIAL_CONDUCTOR || sh.kind == MATERIAL_DIELECTRIC) return !lobe_smooth(sh);
    return sh.kind != MATERIAL_TRANSPARENT;
}

// Whether any leaf of material m has a lobe that visible points evaluate: a photon landing
// on a mix is stored by this, not by the leaf its own draw picked. The eye path already picks
// the leaf its visible point holds, by the mix's factor; deciding the photon's storage by a
// second pick halved the photon light of a mix of a smooth and a rough part (a mirror and a
// diffuse half: 0.499 of its closed form). A leaf's roughness texture counts as rough; a mix
// deeper than the stack is taken as rough (storing a photon no visible point gathers costs a
// slot, never a bias).
bool material_has_rough_leaf(int m) {
    int stack[16];
    int top = 0;
    stack[top++] = m;
    for (int steps = 0; steps < 64 && top > 0; ++steps) {
        int k = stack[--top];
        int kind = material_kind(k);
        if (kind == MATERIAL_MIX) {
            if (top + 2 > 16) return true;
            ivec2 ab = material_mix(k);
            stack[top++] = ab.x;
            stack[top++] = ab.y;
        } else if (kind == MATERIAL_CONDUCTOR) {
            if (material_roughness_texture(k) >= 0 ||
                (material_roughness(k) >= glossy_threshold && material_roughness(k) > 0.0))
                return true;
        } else if (kind != MATERIAL_TRANSPARENT && kind != MATERIAL_DIELECTRIC) {
            return true;  // Lambert, plastic (its diffuse base), translucent
        }
    }
    return top > 0;
}

// The probability that an eye path goes on through the smooth part of the material at wo.
float bsdf_smooth_probability(Shading sh, vec3 wo_world) {
    switch (sh.kind) {
        case MATERIAL_TRANSPARENT: return 1.0;
        case MATERIAL_CONDUCTOR:
        case MATERIAL_DIELECTRIC: return lobe_smooth(sh) ? 1.0 : 0.0;
#ifdef HAS_ROUGH_LOBES
        case MATERIAL_PLASTIC:
            return lobe_smooth(sh) ? plastic_layer_probability(sh, to_local(sh, wo_world)) : 0.0;
#endif
        default: return 0.0;
    }
}

// Cycles' shadow terminator for bumped normals, which it applies to its diffuse closures
// wherever the shading normal is not the smooth one; Frame's shadow_terminator picks the
// Cycles of the user's Blender. Up to 4.x (Chiang, Li and Burley 2019, "Taming the Shadow
// Terminator"): with g = cos(ng, wi) / (cos(n, wi) cos(ng, n)), light from where a tilted
// normal would see the surface lit more than its true orientation fades as -g^3 + g^2 + g
// below g = 1. Without it the diffuse lobe reads 1.1-1.3% brighter than Cycles on a
// normal-mapped plane under a dim world (tests/blender/test_materials.py). 5.x (Conty
// Estevez, Lecocq and Stein 2021, eq. 4-5): Smith's GGX G1 at cos(ng, wi) for alpha^2 =
// tan^2(ng, n) / 8, light on the far side of ng from n black (Cycles' bump_shadowing_term).
float bump_shadowing(Shading sh, vec3 wi_world) {
#ifdef HAS_NORMAL_MAP
    if (shadow_terminator != 0u) {
        float cos_i = dot(sh.ng, wi_world), cos_d = dot(sh.ng, sh.n);
        if (cos_i * cos_d * dot(sh.n, wi_world) < 0.0) return 0.0;
        cos_i = abs(cos_i);
        cos_d = abs(cos_d);
        if (cos_d >= 1.0 || cos_i >= 1.0) return 1.0;
        if (cos_i < 1.0e-6) return 0.0;
        float alpha2 = clamp(0.125 * (1.0 / (cos_d * cos_d) - 1.0), 0.0, 1.0);
        float tan2_i = (1.0 - cos_i * cos_i) / (cos_i * cos_i);
        return 2.0 / (1.0 + sqrt(1.0 + alpha2 * tan2_i));
    }
    float g = dot(sh.ng, wi_world) / max(dot(sh.n, wi_world) * dot(sh.ng, sh.n), 1.0e-9);
    if (g >= 1.0) return 1.0;
    if (g <= 0.0) return 0.0;
    return g * (1.0 + g - g * g);
#else
    return 1.0;
#endif
}

vec3 bsdf_f(Shading sh, vec3 wo_world, vec3 wi_world, bool rough_only, bool adjoint) {
    vec3 wo = to_local(sh, wo_world), wi = to_local(sh, wi_world);
    switch (sh.kind) {
        case MATERIAL_DIFFUSE:
            return wo.z > 0.0 && wi.z > 0.0 ? sh.color / PI * bump_shadowing(sh, wi_world)
                                            : vec3(0.0);
#ifdef HAS_ROUGH_LOBES
        case MATERIAL_TRANSLUCENT:
            return wo.z > 0.0 && wi.z < 0.0 ? sh.color / PI : vec3(0.0);
        case MATERIAL_CONDUCTOR:
            return sh.roughness > 0.0 ? conductor_f(sh, wo, wi) : vec3(0.0);
        case MATERIAL_DIELECTRIC:
            return sh.roughness > 0.0 ? dielectric_f(sh, wo, wi, adjoint) : vec3(0.0);
        case MATERIAL_PLASTIC: {
            vec3 f = plastic_base_f(sh, wo, wi) * bump_shadowing(sh, wi_world);
            if (!(rough_only && lobe_smooth(sh))) f += plastic_layer_f(sh, wo, wi);
            return f;
        }
#endif
        default: return vec3(0.0);
    }
}

// bsdf_f of the lobes whose scatter is of the kinds in the mask (a bit per BOUNCE_ kind of
// common/bounces.glsl): the gather's f where Cycles' Light Paths limits admit only some kinds
// of the visible point's scatter. A glass's reflection is glossy and its refraction
// transmission, as Cycles labels the sampled direction; plastic's base is diffuse and its
// layer glossy, each lobe's own f (Cycles labels a direction by the closure it drew, whose
// share of a direction is its pdf's: the two agree on every one-lobe material).
vec3 bsdf_f_of_kinds(Shading sh, vec3 wo_world, vec3 wi_world, bool rough_only, bool adjoint,
                     uint kinds) {
    if (kinds == 7u) return bsdf_f(sh, wo_world, wi_world, rough_only, adjoint);
    if (kinds == 0u) return vec3(0.0);
    vec3 wo = to_local(sh, wo_world), wi = to_local(sh, wi_world);
    uint kind;
    switch (sh.kind) {
        case MATERIAL_DIFFUSE: kind = BOUNCE_DIFFUSE; break;
        case MATERIAL_TRANSLUCENT: kind = BOUNCE_TRANSMISSION; break;
        case MATERIAL_CONDUCTOR: kind = BOUNCE_GLOSSY; break;
        case MATERIAL_DIELECTRIC: kind = wi.z > 0.0 ? BOUNCE_GLOSSY : BOUNCE_TRANSMISSION; break;
#ifdef HAS_ROUGH_LOBES
        case MATERIAL_PLASTIC: {
            vec3 f = vec3(0.0);
            if ((kinds & (1u << BOUNCE_DIFFUSE)) != 0u)
                f += plastic_base_f(sh, wo, wi) * bump_shadowing(sh, wi_world);
            if ((kinds & (1u << BOUNCE_GLOSSY)) != 0u && !(rough_only && lobe_smooth(sh)))
                f += plastic_layer_f(sh, wo, wi);
            return f;
        }
#endif
        default: return vec3(0.0);
    }
    return (kinds & (1u << kind)) != 0u ? bsdf_f(sh, wo_world, wi_world, rough_only, adjoint)
                                        : vec3(0.0);
}

// The density bsdf_sample draws wi with (0 for the delta lobes).
float bsdf_pdf(Shading sh, vec3 wo_world, vec3 wi_world) {
    vec3 wo = to_local(sh, wo_world), wi = to_local(sh, wi_world);
    switch (sh.kind) {
        case MATERIAL_DIFFUSE: return wo.z > 0.0 && wi.z > 0.0 ? wi.z / PI : 0.0;
#ifdef HAS_ROUGH_LOBES
        case MATERIAL_TRANSLUCENT: return wo.z > 0.0 && wi.z < 0.0 ? -wi.z / PI : 0.0;
        case MATERIAL_CONDUCTOR: return sh.roughness > 0.0 ? conductor_pdf(sh, wo, wi) : 0.0;
        case MATERIAL_DIELECTRIC: return sh.roughness > 0.0 ? dielectric_pdf(sh, wo, wi) : 0.0;
        case MATERIAL_PLASTIC: {
            if (wo.z <= 0.0 || wi.z <= 0.0) return 0.0;
            float p = plastic_layer_probability(sh, wo);
            return p * plastic_layer_pdf(sh, wo, wi) + (1.0 - p) * wi.z / PI;
        }
#endif
        default: return 0.0;
    }
}

// The exact specular lobes of roughness 0: a mirror, and smooth glass chosen by Fresnel.
bool smooth_sample(Shading sh, vec3 wo, float u, bool adjoint, out vec3 wi, out vec3 weight) {
    if (wo.z <= 0.0) return false;
    wi = vec3(-wo.x, -wo.y, wo.z);
    if (sh.kind == MATERIAL_CONDUCTOR) {
        weight = conductor_fresnel(sh, wo.z);
        return true;
    }
    float eta = 1.0 / dielectric_eta(sh), cos_t;
    float F = fresnel_dielectric(wo.z, eta, cos_t);
    if (u < F) {
        weight = (sh.options & OPTION_TINT_REFLECTION) != 0u ? sh.color : vec3(1.0);
        return true;
    }
    wi = vec3(-eta * wo.x, -eta * wo.y, -cos_t);
    weight = adjoint ? sh.color * (eta * eta) : sh.color;  // see the top of this file
    return true;
}

// Draws wi from the whole material at wo; weight = f cos / pdf (adjoint: for photons).
// The lobes of a material are combined by their sampling probabilities (one-sample MIS with
// the balance heuristic, the density being the mixture's).
bool bsdf_sample(Shading sh, vec3 wo_world, vec3 u, bool adjoint, out vec3 wi_world,
                 out vec3 weight) {
    vec3 wo = to_local(sh, wo_world);
    vec3 wi;
    weight = vec3(0.0);
    wi_world = -wo_world;
    if (wo.z <= 0.0) return false;
    switch (sh.kind) {
        case MATERIAL_TRANSPARENT:
            weight = sh.color;
            return true;
        case MATERIAL_DIFFUSE:
        case MATERIAL_TRANSLUCENT: {
            float r = sqrt(u.x), phi = 2.0 * PI * u.y;
            wi = vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u.x)));
            if (sh.kind == MATERIAL_TRANSLUCENT) wi.z = -wi.z;
            weight = sh.color;
            wi_world = to_world(sh, wi);
            return true;
        }
        case MATERIAL_CONDUCTOR:
        case MATERIAL_DIELECTRIC:
            if (sh.roughness == 0.0) {
                if (!smooth_sample(sh, wo, u.z, adjoint, wi, weight)) return false;
                wi_world = to_world(sh, wi);
                return true;
            }
#ifdef HAS_ROUGH_LOBES
            if (sh.kind == MATERIAL_CONDUCTOR ? !conductor_sample(sh, wo, u, wi)
                                              : !dielectric_sample(sh, wo, u, wi))
                return false;
            break;
#else
            return false;
#endif
#ifdef HAS_ROUGH_LOBES
        case MATERIAL_PLASTIC: {
            if (u.z < plastic_layer_probability(sh, wo)) {
                vec3 h = ggx_sample_visible(wo, sh.alpha, u.x, u.y);
                wi = 2.0 * dot(wo, h) * h - wo;
            } else {
                float r = sqrt(u.x), phi = 2.0 * PI * u.y;
                wi = vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u.x)));
            }
            if (wi.z <= 0.0) return false;
            break;
        }
#endif
        default: return false;
    }
    wi_world = to_world(sh, wi);
    float pdf = bsdf_pdf(sh, wo_world, wi_world);
    if (!(pdf > 0.0)) return false;
    weight = bsdf_f(sh, wo_world, wi_world, false, adjoint) * (abs(wi.z) / pdf);
    return true;
}

// The factor 1 / eta^2 that a photon's weight carries through a refraction into wi (the
// adjoint's, see the top of this file), 1 for every other scatter: Russian roulette leaves it
// out, for it only compresses the flux going into the denser medium and expands it coming
// out (through a closed solid the two cancel). A roulette on it dropped 56% of the photons
// entering glass of index 1.5, where a caustic's photons come from: the same flux on fewer
// photons (test_caustic_flux's count through the ball), as the closed model never did.
float photon_refraction_factor(Shading sh, vec3 wi_world) {
    if (sh.kind != MATERIAL_DIELECTRIC || dot(wi_world, sh.n) >= 0.0) return 1.0;
    float etap = dielectric_eta(sh);
    return 1.0 / (etap * etap);
}

// Whether the bounce bsdf_sample(sh, wo_world, u, ...) draws goes through a lobe that eye
// paths follow (lobe_smooth): a photon that took one before landing is a caustic.
bool bsdf_sample_is_smooth(Shading sh, vec3 wo_world, vec3 u) {
    switch (sh.kind) {
        case MATERIAL_CONDUCTOR:
        case MATERIAL_DIELECTRIC: return lobe_smooth(sh);
#ifdef HAS_ROUGH_LOBES
        case MATERIAL_PLASTIC:
            return lobe_smooth(sh) && u.z < plastic_layer_probability(sh, to_local(sh, wo_world));
#endif
        default: return false;
    }
}

// Whether the bounce bsdf_sample(sh, wo_world, u, ...) draws goes through a diffuse lobe
// (Lambert, plastic's base; translucency is a transmission): common/bounces.glsl's kinds.
bool bsdf_sample_is_diffuse(Shading sh, vec3 wo_world, vec3 u) {
    switch (sh.kind) {
        case MATERIAL_DIFFUSE: return true;
#ifdef HAS_ROUGH_LOBES
        case MATERIAL_PLASTIC: return u.z >= plastic_layer_probability(sh, to_local(sh, wo_world));
#endif
        default: return false;
    }
}

// Eye paths through the smooth part of a material (bsdf_smooth_probability > 0): the whole
// material where every lobe is smooth, the layer alone for plastic; weight = f cos / pdf of
// that part.
bool bsdf_sample_smooth(Shading sh, vec3 wo_world, vec3 u, out vec3 wi_world, out vec3 weight) {
#ifndef HAS_ROUGH_LOBES
    return bsdf_sample(sh, wo_world, u, false, wi_world, weight);
#else
    if (sh.kind != MATERIAL_PLASTIC) return bsdf_sample(sh, wo_world, u, false, wi_world, weight);
    vec3 wo = to_local(sh, wo_world);
    weight = vec3(0.0);
    wi_world = -wo_world;
    if (wo.z <= 0.0) return false;
    vec3 h = ggx_sample_visible(wo, sh.alpha, u.x, u.y);
    vec3 wi = 2.0 * dot(wo, h) * h - wo;
    if (wi.z <= 0.0) return false;
    float pdf = plastic_layer_pdf(sh, wo, wi);
    if (!(pdf > 0.0)) return false;
    weight = plastic_layer_f(sh, wo, wi) * (wi.z / pdf);
    wi_world = to_world(sh, wi);
    return true;
#endif
}

// About a smooth shading normal a sampled direction wi may cross the true surface (normal ng)
// to the other side than its lobe meant: it is mirrored back across the surface. Eye paths
// and photons alike; a cut-out's straight-through direction stays.
vec3 on_the_lobes_side(vec3 wi, Shading sh, vec3 ng) {
    vec3 ng_wo = sh.entering ? ng : -ng;
    float meant = dot(wi, sh.n), got = dot(wi, ng_wo);
    if (meant * got <= 0.0 && sh.kind != MATERIAL_TRANSPARENT)
        wi = normalize(wi - 2.0 * got * ng_wo);
    return wi;
}

#endif
