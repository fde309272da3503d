// Image textures: every image sits in its own rectangle of one of two array textures (8-bit
// sRGB, decoded to linear by the sampler; float), laid out by native/render/texture_atlas.h.
// Bilinear filtering is done here with texelFetch so that repeat and clip wrap inside the
// image's rectangle and never bleed into a neighbour.
#ifndef TEXTURES_GLSL
#define TEXTURES_GLSL
#include "common/bindings.glsl"
// (The include resolver splices each file once, wherever it is first named, so includes
// are never placed inside #ifdef; the guard is here.)
#if defined(HAS_TEXTURES) || defined(HAS_ENVIRONMENT_MAP)

// 2 per texture: (x, y, width, height) in its layer, (layer, float 0/1, wrap, 0).
layout(std430, binding = BINDING_TEXTURE_INFO) readonly buffer TextureInfo { ivec4 texture_info[]; };
layout(binding = TEXTURE_UNIT_SRGB_ATLAS) uniform sampler2DArray srgb_atlas;
layout(binding = TEXTURE_UNIT_FLOAT_ATLAS) uniform sampler2DArray float_atlas;

const int WRAP_REPEAT = 0;
const int WRAP_CLIP = 1;

vec4 fetch_texel(ivec4 rect, ivec4 info, ivec2 p) {
    ivec3 at = ivec3(rect.xy + p, info.x);
    return info.y == 0 ? texelFetch(srgb_atlas, at, 0) : texelFetch(float_atlas, at, 0);
}

// Texel (x, y) covers uv [x, x+1] / width: bilinear between the four nearest texel centres.
vec4 sample_texture(int k, vec2 uv) {
    ivec4 rect = texture_info[2 * k];
    ivec4 info = texture_info[2 * k + 1];
    if (info.z == WRAP_CLIP && (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))))
        return vec4(0.0);
    if (info.z == WRAP_REPEAT) uv -= floor(uv);  // keeps the texel arithmetic small
    vec2 xy = uv * vec2(rect.zw) - 0.5;
    vec2 base = floor(xy);
    vec2 f = xy - base;
    ivec2 p0 = ivec2(base), p1 = p0 + 1;
    if (info.z == WRAP_REPEAT) {
        p0 = (p0 % rect.zw + rect.zw) % rect.zw;
        p1 = (p1 % rect.zw + rect.zw) % rect.zw;
    } else {
        p0 = clamp(p0, ivec2(0), rect.zw - 1);
        p1 = clamp(p1, ivec2(0), rect.zw - 1);
    }
    vec4 a = mix(fetch_texel(rect, info, p0), fetch_texel(rect, info, ivec2(p1.x, p0.y)), f.x);
    vec4 b = mix(fetch_texel(rect, info, ivec2(p0.x, p1.y)), fetch_texel(rect, info, p1), f.x);
    return mix(a, b, f.y);
}

#endif
#endif
