// The GGX (Trowbridge-Reitz) microfacet distribution and what the lobes of bsdf.glsl build
// from it, in a shading frame whose z axis is the normal. Blender's roughness r gives
// alpha = r^2. Masking-shadowing is Smith's height-correlated form, G2 = 1 / (1 + L(o) + L(i)),
// as Cycles uses; normals are sampled from the distribution of visible normals (Heitz 2018,
// "Sampling the GGX distribution of visible normals"), so a sample's weight is G2 / G1(o)
// times Fresnel, never D. native/render/microfacet_tables.cpp integrates the same functions
// on the CPU for the albedo tables the energy compensation reads.
#ifndef MICROFACET_GLSL
#define MICROFACET_GLSL

// Below this alpha the lobe is sampled and evaluated as if alpha were this: GGX's D then
// still fits a float for every normal.
const float GGX_MIN_ALPHA = 1.0e-4;

float ggx_alpha(float roughness) { return max(roughness * roughness, GGX_MIN_ALPHA); }

// D(m) for a unit normal m in the frame (m.z > 0). The denominator
// cos^2 (a2 - 1) + 1 = a2 cos^2 + sin^2 is formed from sin^2 = x^2 + y^2 directly: near the
// peak of a smooth lobe 1 - cos^2 would cancel to nothing in float.
float ggx_d(vec3 m, float a2) {
    float d = a2 * m.z * m.z + (m.x * m.x + m.y * m.y);
    return a2 / (PI * d * d);
}

// Smith's Lambda for a direction at cos(theta) = c to the normal.
float ggx_lambda(float c, float a2) {
    float c2 = c * c;
    float t2 = max(0.0, 1.0 - c2) / max(c2, 1.0e-20);
    return 0.5 * (sqrt(1.0 + a2 * t2) - 1.0);
}

float ggx_g1(float c, float a2) { return 1.0 / (1.0 + ggx_lambda(c, a2)); }

float ggx_g2(float co, float ci, float a2) {
    return 1.0 / (1.0 + ggx_lambda(co, a2) + ggx_lambda(ci, a2));
}

// A normal visible from wo (wo.z > 0), with density G1(wo) max(0, wo.m) D(m) / wo.z.
vec3 ggx_sample_visible(vec3 wo, float a, float u1, float u2) {
    vec3 v = normalize(vec3(a * wo.x, a * wo.y, wo.z));  // to the hemisphere configuration
    float len2 = v.x * v.x + v.y * v.y;
    vec3 t1 = len2 > 0.0 ? vec3(-v.y, v.x, 0.0) * inversesqrt(len2) : vec3(1.0, 0.0, 0.0);
    vec3 t2 = cross(v, t1);
    float r = sqrt(u1);
    float phi = 2.0 * PI * u2;
    float p1 = r * cos(phi);
    float s = 0.5 * (1.0 + v.z);
    float p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * r * sin(phi);
    vec3 h = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * v;
    return normalize(vec3(a * h.x, a * h.y, max(1.0e-7, h.z)));  // back to the ellipsoid
}

float ggx_visible_pdf(vec3 wo, vec3 m, float a2) {
    return ggx_g1(wo.z, a2) * max(0.0, dot(wo, m)) * ggx_d(m, a2) / wo.z;
}

// The density of a reflection wi = reflect(wo, h) drawn through ggx_sample_visible, for wo and
// wi above the surface: G1(wo) D(h) / (4 wo.z), the visible density over the Jacobian
// 4 wo.h with wo.h cancelled. Not cancelled, it went wrong at grazing incidence: wo and its
// mirror direction are nearly opposite in the tangent plane, so wo + wi, and the half vector
// normalised from it, holds little but the rounding of their tangent components (about 1e-7
// against a normal component of 2 wo.z); wo.h then came out 0 or negative, the density 0,
// while f, which has no such factor, kept D(h) / (4 wo.z wi.z): a sample weighed up to
// 1e14 (session 22: the showcase's gold ring of roughness 0.02 at its silhouette, white
// dots of 4.6e8 after 6,351 passes). Here f and the density share D(h) and differ by
// G2 / G1 <= 1, however the rounding tilts h.
float ggx_reflection_pdf(vec3 wo, vec3 h, float a2) {
    return ggx_g1(wo.z, a2) * ggx_d(h, a2) / (4.0 * wo.z);
}

// Unpolarised Fresnel reflectance of a smooth dielectric; eta = n_incident / n_transmitted.
float fresnel_dielectric(float cos_i, float eta, out float cos_t) {
    float sin2_t = eta * eta * max(0.0, 1.0 - cos_i * cos_i);
    if (sin2_t >= 1.0) {
        cos_t = 0.0;
        return 1.0;  // total internal reflection
    }
    cos_t = sqrt(1.0 - sin2_t);
    float rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    float rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

vec3 fresnel_schlick(vec3 f0, float c) {
    float k = 1.0 - clamp(c, 0.0, 1.0);
    float k2 = k * k;
    return f0 + (1.0 - f0) * (k2 * k2 * k);
}

// The hemispherical average 2 int F(mu) mu dmu of Schlick's Fresnel.
vec3 fresnel_schlick_average(vec3 f0) { return f0 + (1.0 - f0) / 21.0; }

#endif
