// Materials at a surface point. Scenes whose materials are all Lambert, mirror or smooth
// glass compile the closed model below (bsdf_eval, scatter_specular); the others compile the
// lobes of common/lobes.glsl (HAS_MICROFACET).
#ifndef BSDF_GLSL
#define BSDF_GLSL

#include "common/scene_buffers.glsl"
#include "common/surface.glsl"
#include "common/textures.glsl"
#include "common/microfacet.glsl"

vec3 material_color(int m) { return materials[MATERIAL_STRIDE * m].xyz; }
int material_kind(int m) { return int(materials[MATERIAL_STRIDE * m].w); }
vec3 material_emission(int m) { return materials[MATERIAL_STRIDE * m + 1].xyz; }
float material_ior(int m) { return materials[MATERIAL_STRIDE * m + 1].w; }
int material_texture(int m) { return floatBitsToInt(materials[MATERIAL_STRIDE * m + 2].x); }
int material_flags(int m) { return floatBitsToInt(materials[MATERIAL_STRIDE * m + 2].y); }

// The emission seen at a surface of material `root` (the triangle's own) whose leaf `m` is
// hit at point `at`: the leaf's radiance times the root's emission texture (HAS_EMISSION_TEXTURE).
vec3 material_emission_at(int root, int m, TexturePoint at) {
#if defined(HAS_EMISSION_TEXTURE) && defined(HAS_TEXTURES)
    int k = floatBitsToInt(materials[MATERIAL_STRIDE * root + 5].x);
    if (k >= 0) return material_emission(m) * sample_texture(k, at).rgb;
#endif
    return material_emission(m);
}

// Flags (native/render/area_lights.h): area-light surfaces add their emission and let rays
// through; some surfaces are hidden from camera rays, some from the eye path's later rays;
// some cast no shadow (photons and shadow rays pass through them).
const int MATERIAL_LIGHT_SURFACE = 1;
const int MATERIAL_HIDDEN_FROM_CAMERA = 2;
const int MATERIAL_ONE_SIDED_EMISSION = 4;
const int MATERIAL_CASTS_NO_SHADOW = 8;
const int MATERIAL_MAY_BE_TRANSPARENT = 16;
const int MATERIAL_HIDDEN_FROM_REFLECTIONS = 32;
const int MATERIAL_VERTEX_COLOR = 64;

// A material's colour at a surface point: its own, times its base-colour texture at `at`, times
// the interpolated vertex colour where the material asks for it (Blender's Color Attribute
// node, glTF's COLOR_0: base colour = factor x texture x COLOR_0).
vec3 material_color_at(int m, TexturePoint at, vec3 vertex_color) {
    vec3 c = material_color(m);
#ifdef HAS_TEXTURES
    int k = material_texture(m);
    if (k >= 0) c *= sample_texture(k, at).rgb;
#endif
#ifdef HAS_VERTEX_COLORS
    if ((material_flags(m) & MATERIAL_VERTEX_COLOR) != 0) c *= vertex_color;
#endif
    return c;
}

// The surface's colour: its material's at the hit.
vec3 surface_color(Surface s) { return material_color_at(s.material, texture_point(s), s.vertex_color); }

// f(wo, wi) of the material's non-delta lobes at a surface point, without the cosine:
// what light sampling weighs a light's radiance by. `n` is the shading normal on the side
// wo leaves from; wi points away from the surface too. Lambert is the only such lobe so
// far (wo unused; the photon gather likewise tests only the incoming side); glossy lobes
// add their terms here.
vec3 bsdf_eval(int m, vec3 color, vec3 n, vec3 wo, vec3 wi) {
    if (material_kind(m) != MATERIAL_DIFFUSE || dot(n, wi) <= 0.0) return vec3(0.0);
    return color / PI;
}

// Scatters `dir` off a specular surface (conductor or dielectric), choosing reflection or
// refraction by Fresnel with probability equal to the reflectance, so the weight is the
// colour alone on eye paths (Cycles' convention: no factor for the change of solid angle, so
// a window of one plane or a camera inside water renders as in Cycles) and, for photons,
// times eta^2, that kernel's adjoint (Veach's thesis, section 5.2; through a closed solid
// the factors cancel). `n` is the shading normal on the geometric normal's side; returns the
// new direction and multiplies `weight`.
vec3 scatter_specular(int m, vec3 color, vec3 dir, vec3 n, vec3 ng, float u, bool radiance,
                      inout vec3 weight) {
#ifdef HAS_DIELECTRIC
    if (material_kind(m) == MATERIAL_DIELECTRIC) {
        bool entering = dot(dir, ng) < 0.0;
        vec3 nn = entering ? n : -n;
        float eta = entering ? 1.0 / material_ior(m) : material_ior(m);
        float cos_i = min(1.0, -dot(dir, nn));
        float cos_t;
        float f = fresnel_dielectric(cos_i, eta, cos_t);
        if (u < f) return reflect(dir, nn);
        weight *= radiance ? color : color * (eta * eta);
        return normalize(eta * dir + (eta * cos_i - cos_t) * nn);
    }
#endif
    weight *= color;
    return reflect(dir, dot(dir, n) < 0.0 ? n : -n);
}

#endif
