// A material record's fields and a material's colour at a surface point; the lobes that
// scatter light are common/lobes.glsl's.
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

#endif
