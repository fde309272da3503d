// Image textures: every image sits in its own rectangle of one of two array textures (8-bit
// sRGB bytes, read as UNORM; float), laid out by native/render/texture_atlas.h. Filtering
// (bilinear, or Closest's one texel) is done here with texelFetch so that every extension
// wraps inside the image's rectangle and never bleeds into a neighbour. 8-bit sRGB images are
// filtered as bytes and the result decoded to linear, as Cycles does
// (NODE_IMAGE_COMPRESS_AS_SRGB in kernel/svm/image.h): a GL sRGB format would decode each
// texel before filtering, which reads brighter across colour edges (the decode is convex).
#ifndef TEXTURES_GLSL
#define TEXTURES_GLSL
#include "common/bindings.glsl"
#include "common/records.glsl"
// (The include resolver splices each file once, wherever it is first named, so includes
// are never placed inside #ifdef; the guard is here.)

// Where on a surface textures are looked up: its mesh uv, and its world position, which
// textures on Blender's Generated and Object coordinates read (HAS_POSITION_TEXTURES).
struct TexturePoint {
    vec2 uv;
    vec3 position;
};

#if defined(HAS_TEXTURES) || defined(HAS_ENVIRONMENT_MAP)

// One record per texture (GpuTexture in native/render/gpu_layout.h): its rectangle in its
// layer, (layer, float 0/1, wrap, TEXTURE_FROM_*), and the affine map to the image's uv:
// from the mesh's uv, (u, v, 1) (Blender's Mapping node on the UVs), or from the world
// position, (p, 1) (Generated and Object coordinates, the object's inverse transform and
// texture space folded in: addon/export/texture_mapping.py).
struct TextureRecord {
    ivec4 rect;
    ivec4 info;
    vec4 uv_map_u;
    vec4 uv_map_v;
};
layout(std430, binding = BINDING_TEXTURE_INFO) readonly buffer TextureInfo { TextureRecord texture_records[]; };
layout(binding = TEXTURE_UNIT_SRGB_ATLAS) uniform sampler2DArray srgb_atlas;
layout(binding = TEXTURE_UNIT_FLOAT_ATLAS) uniform sampler2DArray float_atlas;

// The extensions (WRAP_*) and the sources (TEXTURE_FROM_*) are in common/records.glsl.

ivec2 texture_size(int k) { return texture_records[k].rect.zw; }

// Where texture k is looked up for mesh uv (a texture on the uvs: the environment's, a
// normal or bump map's, which the add-on never puts on position).
vec2 texture_uv(int k, vec2 uv) {
    vec3 h = vec3(uv, 1.0);
    return vec2(dot(texture_records[k].uv_map_u.xyz, h), dot(texture_records[k].uv_map_v.xyz, h));
}

// Where texture k is looked up at a surface point.
vec2 texture_uv(int k, TexturePoint at) {
#ifdef HAS_POSITION_TEXTURES
    if (texture_records[k].info.w == TEXTURE_FROM_POSITION) {
        vec4 h = vec4(at.position, 1.0);
        return vec2(dot(texture_records[k].uv_map_u, h), dot(texture_records[k].uv_map_v, h));
    }
#endif
    return texture_uv(k, at.uv);
}

// A texel index along an axis of n texels under the extension, as Cycles' wrap_periodic,
// wrap_clamp and wrap_mirror; Clip gives -1 outside the image (read as transparent black).
// (GLSL leaves % of a negative operand undefined: llvmpipe's (-1 % 5 + 5) % 5 gave 0, not 4,
// so negative indices are folded by hand.)
int wrap_index(int i, int n, int wrap) {
    if (wrap == WRAP_REPEAT) return i >= 0 ? i % n : n - 1 - (-1 - i) % n;
    if (wrap == WRAP_EXTEND) return clamp(i, 0, n - 1);
    if (wrap == WRAP_MIRROR) {
        int m = abs(i + (i < 0 ? 1 : 0)) % (2 * n);
        return m >= n ? 2 * n - m - 1 : m;
    }
    return i < 0 || i >= n ? -1 : i;
}

ivec2 wrap_texel(ivec2 p, ivec2 n, int wrap) {
    return ivec2(wrap_index(p.x, n.x, wrap), wrap_index(p.y, n.y, wrap));
}

vec4 fetch_texel(ivec4 rect, ivec4 info, ivec2 p) {
    if (p.x < 0 || p.y < 0) return vec4(0.0);  // clipped
    ivec3 at = ivec3(rect.xy + p, info.x);
    return info.y == 0 ? texelFetch(srgb_atlas, at, 0) : texelFetch(float_atlas, at, 0);
}

// The sRGB EOTF (IEC 61966-2-1) on colour; alpha is stored linear. Cycles'
// color_srgb_to_linear (util/color.h).
vec4 srgb_to_linear(vec4 c) {
    vec3 low = c.rgb / 12.92;
    vec3 high = pow((max(c.rgb, vec3(0.04045)) + 0.055) / 1.055, vec3(2.4));
    return vec4(mix(high, low, lessThanEqual(c.rgb, vec3(0.04045))), c.a);
}

// Closest: the one texel st falls in, floor(st size), wrapped as Linear's (Cycles'
// interp_closest, whose texel centres are those of interp_linear).
vec4 closest_texel(ivec4 rect, ivec4 info, int wrap, vec2 st) {
    return fetch_texel(rect, info, wrap_texel(ivec2(floor(st * vec2(rect.zw))), rect.zw, wrap));
}

// Texture k at the image's own uv st (texel (x, y) covers [x, x+1] / width). Linear: bilinear
// between the four nearest texel centres, each wrapped by the extension (Cycles'
// interp_linear); Closest: closest_texel. Bytes are filtered, then decoded.
vec4 sample_texture_st(int k, vec2 st) {
    ivec4 rect = texture_records[k].rect;
    ivec4 info = texture_records[k].info;
    int wrap = info.z & TEXTURE_WRAP_MASK;
    // Reduced to one period (Repeat 1, Mirror 2), which keeps the texel arithmetic small;
    // Clip and Extend read the same texels anywhere past the edges.
    if (wrap == WRAP_REPEAT) st -= floor(st);
    else if (wrap == WRAP_MIRROR) st -= 2.0 * floor(0.5 * st);
    else st = clamp(st, vec2(-1.0), vec2(2.0));
    vec4 filtered;
    if ((info.z >> TEXTURE_INTERPOLATION_SHIFT) == INTERPOLATION_CLOSEST) {
        filtered = closest_texel(rect, info, wrap, st);
    } else {
        vec2 xy = st * vec2(rect.zw) - 0.5;
        vec2 base = floor(xy);
        vec2 f = xy - base;
        ivec2 p0 = ivec2(base), p1 = p0 + 1;
        ivec2 q0 = wrap_texel(p0, rect.zw, wrap), q1 = wrap_texel(p1, rect.zw, wrap);
        vec4 a = mix(fetch_texel(rect, info, q0), fetch_texel(rect, info, ivec2(q1.x, q0.y)), f.x);
        vec4 b = mix(fetch_texel(rect, info, ivec2(q0.x, q1.y)), fetch_texel(rect, info, q1), f.x);
        filtered = mix(a, b, f.y);
    }
    return info.y == 0 ? srgb_to_linear(filtered) : filtered;
}

// Texture k at mesh uv (textures on the uvs only), and at a surface point.
vec4 sample_texture(int k, vec2 uv) { return sample_texture_st(k, texture_uv(k, uv)); }
vec4 sample_texture(int k, TexturePoint at) { return sample_texture_st(k, texture_uv(k, at)); }

#endif
#endif
