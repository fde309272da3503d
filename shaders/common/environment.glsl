// The world's radiance: a constant colour, or an equirectangular map in Blender's mapping
// times that colour, with photons leaving the map in proportion to its radiance
// (native/render/environment_map.h builds the distribution).
#ifndef ENVIRONMENT_GLSL
#define ENVIRONMENT_GLSL

#include "common/bindings.glsl"
#include "common/frame.glsl"
#include "common/textures.glsl"

#ifdef HAS_ENVIRONMENT_MAP

// Blender's (Cycles') equirectangular mapping in the map's frame: u = 0.5 - atan2(y, x) / 2 pi
// (+X at the centre, +Y at u = 0.25), v = 0.5 + elevation / pi.
vec2 environment_uv(vec3 world_dir) {
    vec3 d = mat3(environment_from_world) * world_dir;
    return vec2(0.5 - atan(d.y, d.x) / (2.0 * PI), atan(d.z, length(d.xy)) / PI + 0.5);
}

vec3 environment_direction(vec2 uv) {
    float phi = (0.5 - uv.x) * 2.0 * PI;
    float elevation = (uv.y - 0.5) * PI;
    vec3 d = vec3(cos(elevation) * cos(phi), cos(elevation) * sin(phi), sin(elevation));
    return normalize(transpose(mat3(environment_from_world)) * d);
}

#ifdef USES_EMITTERS
// Marginal CDF over rows (height + 1 values), then per row a conditional CDF (width + 1).
layout(std430, binding = BINDING_ENVIRONMENT_CDF) readonly buffer EnvironmentCdf { float environment_cdf[]; };

// The largest i in [lo, hi) with cdf[i] <= u.
uint search_cdf(uint first, uint count, float u) {
    uint lo = 0u, hi = count;
    while (hi - lo > 1u) {
        uint mid = (lo + hi) / 2u;
        if (environment_cdf[first + mid] <= u) lo = mid;
        else hi = mid;
    }
    return lo;
}

// A direction with pdf (per solid angle) proportional to the map's weights:
// pdf = p(texel) * width * height / (2 pi^2 sin(theta)).
vec3 sample_environment(float u1, float u2, float u3, float u4, out float pdf) {
    uint w = uint(environment_cdf_width), h = uint(environment_cdf_height);
    uint row = search_cdf(0u, h, u1);
    uint first = h + 1u + row * (w + 1u);
    uint col = search_cdf(first, w, u2);
    float p_row = environment_cdf[row + 1u] - environment_cdf[row];
    float p_col = environment_cdf[first + col + 1u] - environment_cdf[first + col];
    vec2 uv = (vec2(col, row) + vec2(u3, u4)) / vec2(w, h);
    float sin_theta = sin(uv.y * PI);
    pdf = p_row * p_col * float(w * h) / (2.0 * PI * PI * max(sin_theta, 1e-7));
    return environment_direction(uv);
}

// The density sample_environment draws world_dir with.
float environment_pdf(vec3 world_dir) {
    uint w = uint(environment_cdf_width), h = uint(environment_cdf_height);
    vec2 uv = environment_uv(world_dir);
    uint row = min(uint(uv.y * float(h)), h - 1u);
    uint col = min(uint(uv.x * float(w)), w - 1u);
    uint first = h + 1u + row * (w + 1u);
    float p_row = environment_cdf[row + 1u] - environment_cdf[row];
    float p_col = environment_cdf[first + col + 1u] - environment_cdf[first + col];
    float sin_theta = sin(uv.y * PI);
    return p_row * p_col * float(w * h) / (2.0 * PI * PI * max(sin_theta, 1e-7));
}
#endif
#endif

// Radiance arriving along -world_dir from the world (world_dir points away from the scene).
vec3 environment_radiance(vec3 world_dir) {
#ifdef HAS_ENVIRONMENT_MAP
    return world_radiance * sample_texture(environment_texture, environment_uv(world_dir)).rgb;
#else
    return world_radiance;
#endif
}

#endif
