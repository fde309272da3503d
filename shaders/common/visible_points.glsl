// A pixel's visible point as the gather reads it, in the 4 vec4 of `visible_points`
// (common/sppm_buffers.glsl): (position, leaf material id or -1), (eye-path throughput, flag
// word), (u, v, shading normal on wo's side, wo: both pack_octahedral's 30 bits), (vertex
// colour at the point or 1, the eye subpath's bounce word). The flag word holds the bits
// below and, from VISIBLE_POINT_NORMAL_SHIFT, the geometric normal on wo's side. The bounce
// word (common/bounces.glsl) counts the eye path's scatters before the point, as a float
// (exact: below 2^22). Include after common/sppm_buffers.glsl and common/surface.glsl.
//
// Four rather than five vec4: the two directions packed (about 1e-4 radians) made the eye
// stage 1.83 -> 1.58 ms at 1920x1080 on the H100 (million:1M), the write of the two
// vec4s being what the one material model's visible point had added to it.
#ifndef VISIBLE_POINTS_GLSL
#define VISIBLE_POINTS_GLSL

const uint VISIBLE_POINT_ROUGH_ONLY = 1u;  // the smooth lobes were followed: leave them out
const uint VISIBLE_POINT_ENTERING = 2u;   // wo is on the geometric front (a dielectric's outside)
// Bits 2-31 hold the geometric normal on wo's side (pack_octahedral), which the side test and
// with HAS_NORMAL_MAP the diffuse lobes read (bump_shadowing in common/lobes.glsl).
const uint VISIBLE_POINT_NORMAL_SHIFT = 2u;

struct VisiblePoint {
    vec3 position;
    float material;  // the leaf's id, -1 for none
    vec3 weight;     // the eye path's throughput
    uint flags;
    vec2 uv;
    vec3 normal;     // shading normal on wo's side
    vec3 wo;
    vec3 vertex_color;
    uint bounces;
};

void store_visible_point(uint i, VisiblePoint p) {
    uint at = VISIBLE_POINT_VEC4 * i;
    visible_points[at + 0u] = vec4(p.position, p.material);
    visible_points[at + 1u] = vec4(p.weight, uintBitsToFloat(p.flags));
    visible_points[at + 2u] = vec4(p.uv, uintBitsToFloat(pack_octahedral(p.normal)),
                                   uintBitsToFloat(pack_octahedral(p.wo)));
    visible_points[at + 3u] = vec4(p.vertex_color, float(p.bounces));
}

// The point's position and material alone: w < 0 where the pixel has none.
vec4 visible_point_position(uint i) { return visible_points[VISIBLE_POINT_VEC4 * i]; }

VisiblePoint load_visible_point(uint i) {
    uint at = VISIBLE_POINT_VEC4 * i;
    vec4 a = visible_points[at + 0u], b = visible_points[at + 1u];
    vec4 c = visible_points[at + 2u], d = visible_points[at + 3u];
    return VisiblePoint(a.xyz, a.w, b.xyz, floatBitsToUint(b.w), c.xy,
                        unpack_octahedral(floatBitsToUint(c.z)),
                        unpack_octahedral(floatBitsToUint(c.w)), d.rgb, uint(d.w));
}

#endif
