// A material record's fields and a material's colour at a surface point; the lobes that
// scatter light are common/lobes.glsl's.
#ifndef BSDF_GLSL
#define BSDF_GLSL

#include "common/scene_buffers.glsl"
#include "common/surface.glsl"
#include "common/textures.glsl"
#include "common/microfacet.glsl"

vec3 material_color(int m) { return material_record(m, MATERIAL_COLOR).xyz; }
int material_kind(int m) { return int(material_record(m, MATERIAL_COLOR).w); }
vec3 material_emission(int m) { return material_record(m, MATERIAL_EMISSION).xyz; }
float material_ior(int m) { return material_record(m, MATERIAL_EMISSION).w; }
int material_texture(int m) { return floatBitsToInt(material_record(m, MATERIAL_TEXTURES).x); }
int material_flags(int m) { return floatBitsToInt(material_record(m, MATERIAL_TEXTURES).y); }
int material_emission_texture(int m) {
    return floatBitsToInt(material_record(m, MATERIAL_EMISSION_TEXTURE).x);
}

// The emission seen at a surface of material `root` (the triangle's own) whose leaf `m` is
// hit at point `at`: the leaf's radiance times the root's emission texture (HAS_EMISSION_TEXTURE).
vec3 material_emission_at(int root, int m, TexturePoint at) {
#if defined(HAS_EMISSION_TEXTURE) && defined(HAS_TEXTURES)
    int k = material_emission_texture(root);
    if (k >= 0) return material_emission(m) * sample_texture(k, at).rgb;
#endif
    return material_emission(m);
}

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
