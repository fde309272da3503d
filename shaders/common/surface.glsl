// What a ray hit: position, normals and material, read from the packed MTBVH triangles.
#ifndef SURFACE_GLSL
#define SURFACE_GLSL

#include "common/mtbvh.glsl"
#include "common/scene_buffers.glsl"
#include "common/textures.glsl"

// The unit normal of a triangle's winding. The edges are scaled by their largest component
// first: the cross product squares them, which overflows or underflows a float for
// triangles far larger or smaller than unit size.
vec3 triangle_normal(vec3 a, vec3 b, vec3 c) {
    vec3 e1 = b - a, e2 = c - a;
    float m = max(max(max(abs(e1.x), abs(e1.y)), max(abs(e1.z), abs(e2.x))),
                  max(abs(e2.y), abs(e2.z)));
    return normalize(cross(e1 / m, e2 / m));
}

// A unit vector in the low 30 bits: the octahedral encoding, 15 bits per coordinate, as
// pack_tangent writes it (native/scene/tangent_space.cpp).
vec3 unpack_octahedral(uint bits) {
    vec2 o = vec2(float(int(bits & 0x7FFFu) - 16383),
                  float(int((bits >> 15) & 0x7FFFu) - 16383)) / 16383.0;
    vec3 t = vec3(o, 1.0 - abs(o.x) - abs(o.y));
    if (t.z < 0.0)
        t.xy = (1.0 - abs(o.yx)) * vec2(o.x >= 0.0 ? 1.0 : -1.0, o.y >= 0.0 ? 1.0 : -1.0);
    return normalize(t);
}

uint pack_octahedral(vec3 v) {
    vec3 t = v / (abs(v.x) + abs(v.y) + abs(v.z));
    vec2 o = t.z >= 0.0 ? t.xy
                        : (1.0 - abs(t.yx)) * vec2(t.x >= 0.0 ? 1.0 : -1.0, t.y >= 0.0 ? 1.0 : -1.0);
    uvec2 q = uvec2(ivec2(round(clamp(o, -1.0, 1.0) * 16383.0)) + 16383);
    return (q.x & 0x7FFFu) | (q.y & 0x7FFFu) << 15;
}

#ifdef HAS_NORMAL_MAP
// GpuMaterial::normal_map (native/render/gpu_layout.h): 0, or the texture's index + 1 in the
// low 15 bits, bit 15 for a bump map, the strength as a half float in the high 16; a bump
// map's distance is a half float in the high 16 bits of the options.
uint material_normal_map(int m) { return floatBitsToUint(material_record(m, MATERIAL_OPTIONS).w); }
const uint NORMAL_MAP_BUMP = 0x8000u;
float material_bump_distance(int m) {
    return unpackHalf2x16(floatBitsToUint(material_record(m, MATERIAL_OPTIONS).x) >> 16).x;
}

// pack_tangent's word: the direction, and the bitangent's sign in bit 31.
vec4 unpack_tangent(float word) {
    uint bits = floatBitsToUint(word);
    return vec4(unpack_octahedral(bits), (bits & 0x80000000u) != 0u ? -1.0 : 1.0);
}

// Blender's Normal Map node in tangent space (as Cycles' svm_node_normal_map): the texel,
// 2 rgb - 1, in the frame (t, sign n x t, n) of the interpolated normal n as the mesh has it,
// then blended with n by the strength. t is made orthogonal to n here, as MikkTSpace's
// per-pixel reconstruction does.
vec3 normal_mapped(int material, vec3 n, vec4 tangent, vec2 uv) {
    uint word = material_normal_map(material);
#ifdef HAS_TEXTURES
    if (word != 0u && (word & NORMAL_MAP_BUMP) == 0u) {
        vec3 c = 2.0 * sample_texture(int(word & 0x7FFFu) - 1, uv).rgb - 1.0;
        vec3 t = tangent.xyz - n * dot(n, tangent.xyz);
        float lt = length(t);
        if (lt > 1.0e-6) {
            t /= lt;
            vec3 mapped = c.x * t + c.y * tangent.w * cross(n, t) + c.z * n;
            float lm = length(mapped);
            if (lm > 0.0) {
                float strength = unpackHalf2x16(word >> 16).x;
                vec3 blended = n + (mapped / lm - n) * strength;
                float lb = length(blended);
                if (lb > 0.0) return blended / lb;
            }
        }
    }
#endif
    return n;
}
#endif

#ifdef HAS_NORMAL_MAP
// Blender's Bump node with an image's luminance as its Height (as Cycles' svm_node_set_bump):
// n' = normalize(n - distance grad h), then blended with n by the strength. grad h is the
// height's gradient on the triangle: dh/du grad u + dh/dv grad v, the derivatives by central
// differences half a texel either side (exact for the bilinear texture within a texel), and
// grad u, grad v the dual basis of the triangle's dp/du, dp/dv in the plane normal to n.
vec3 bump_mapped(int material, vec3 n, vec2 uv, vec3 p0, vec3 p1, vec3 p2, vec2 w0, vec2 w1,
                 vec2 w2) {
    uint word = material_normal_map(material);
#ifdef HAS_TEXTURES
    if ((word & NORMAL_MAP_BUMP) != 0u) {
        int k = int(word & 0x7FFFu) - 1;
        // The differences in the image's own uv st, then through its uv map's linear part
        // to the mesh's uv (chain rule: dh/du = dh/ds ds/du + dh/dt dt/du).
        vec2 texel = 0.5 / vec2(texture_size(k));
        vec2 st = texture_uv(k, uv);
        const vec3 gray = vec3(0.2126, 0.7152, 0.0722);  // Blender's colour to float
        float dhds = dot(sample_texture_st(k, st + vec2(texel.x, 0.0)).rgb -
                         sample_texture_st(k, st - vec2(texel.x, 0.0)).rgb, gray) / (2.0 * texel.x);
        float dhdt = dot(sample_texture_st(k, st + vec2(0.0, texel.y)).rgb -
                         sample_texture_st(k, st - vec2(0.0, texel.y)).rgb, gray) / (2.0 * texel.y);
        vec3 map_s = texture_records[k].uv_map_u.xyz, map_t = texture_records[k].uv_map_v.xyz;
        float dhdu = dhds * map_s.x + dhdt * map_t.x;
        float dhdv = dhds * map_s.y + dhdt * map_t.y;
        // dp/du and dp/dv from p - p0 = e1 a + e2 b, uv - w0 = d1 a + d2 b.
        vec3 e1 = p1 - p0, e2 = p2 - p0;
        vec2 d1 = w1 - w0, d2 = w2 - w0;
        float det = d1.x * d2.y - d2.x * d1.y;
        if (det != 0.0) {
            vec3 dpdu = (e1 * d2.y - e2 * d1.y) / det;
            vec3 dpdv = (e2 * d1.x - e1 * d2.x) / det;
            // The dual basis: grad u . dpdu = 1, grad u . dpdv = 0, both normal to n.
            vec3 ru = cross(dpdv, n), rv = cross(n, dpdu);
            float j = dot(dpdu, ru);
            if (j != 0.0) {
                vec3 grad = (dhdu * ru + dhdv * rv) / j;
                float distance = material_bump_distance(material);
                float strength = unpackHalf2x16(word >> 16).x;
                vec3 bumped = normalize(n - distance * grad);
                vec3 blended = strength * bumped + (1.0 - strength) * n;
                float lb = length(blended);
                if (lb > 0.0) return blended / lb;
            }
        }
    }
#endif
    return n;
}
#endif

struct Surface {
    vec3 position;
    vec3 geometric_normal;  // from the winding: emitters face this way
    vec3 normal;            // shading normal, on the same side as the geometric one
    int material;
    vec2 uv;                // texture coordinates (HAS_TEXTURES only)
    vec3 vertex_color;      // linear, interpolated (HAS_VERTEX_COLORS only; else white)
};

// Where textures are looked up at a surface point: its uv and world position.
TexturePoint texture_point(Surface s) { return TexturePoint(s.uv, s.position); }

#ifdef GLSLPPM_INSTANCES
// A surface found in an instance's space, moved to world space: the position by A x + T
// (interpolated in the instance, where its coordinates are small, and moved once), normals
// by A^-T, the material by the instance's offset (native/bvh/two_level_bvh.h). A mirrored
// instance (det A < 0) keeps its front side, as in Blender: the winding's normal is moved
// like the others rather than recomputed from the mirrored winding.
void instance_surface_to_world(inout Surface s, int instance) {
    int base = INSTANCE_RECORD_VEC4 * instance;
    vec4 i0 = instances[base];
    vec4 i1 = instances[base + 1];
    vec4 i2 = instances[base + 2];
    vec4 a0 = instances[base + 3];
    vec4 a1 = instances[base + 4];
    vec4 a2 = instances[base + 5];
    s.position = vec3(dot(a0.xyz, s.position), dot(a1.xyz, s.position),
                      dot(a2.xyz, s.position)) + vec3(a0.w, a1.w, a2.w);
    // A^-T n: the rows of A^-1 weighted by n's components.
    vec3 ng = i0.xyz * s.geometric_normal.x + i1.xyz * s.geometric_normal.y +
              i2.xyz * s.geometric_normal.z;
    s.geometric_normal = normalize(ng);
    vec3 n = i0.xyz * s.normal.x + i1.xyz * s.normal.y + i2.xyz * s.normal.z;
    s.normal = normalize(n);
    if (dot(s.normal, s.geometric_normal) < 0.0) s.normal = -s.normal;
    s.material += bvh_instance_bases(instance).w;
}
#endif

Surface surface_at(Ray ray, Hit hit) {
    int t = hit.triangle;
    vec4 a = triangles[3 * t + 0];
    vec4 b = triangles[3 * t + 1];
    vec4 c = triangles[3 * t + 2];
    Surface s;
    // Interpolating the vertices is more accurate than origin + t * dir far from the origin.
    s.position = a.xyz + hit.u * (b.xyz - a.xyz) + hit.v * (c.xyz - a.xyz);
    s.geometric_normal = triangle_normal(a.xyz, b.xyz, c.xyz);
    s.material = floatBitsToInt(a.w);
#ifdef HAS_TEXTURES
    vec4 uv01 = vertex_uvs[2 * t + 0];
    vec2 uv2 = vertex_uvs[2 * t + 1].xy;
    s.uv = (1.0 - hit.u - hit.v) * uv01.xy + hit.u * uv01.zw + hit.v * uv2;
#else
    s.uv = vec2(0.0);
#endif
#ifdef HAS_VERTEX_COLORS
    s.vertex_color = (1.0 - hit.u - hit.v) * vertex_colors[3 * t + 0].rgb +
                     hit.u * vertex_colors[3 * t + 1].rgb + hit.v * vertex_colors[3 * t + 2].rgb;
#else
    s.vertex_color = vec3(1.0);
#endif
#ifdef HAS_NORMALS
    vec3 w = vec3(1.0 - hit.u - hit.v, hit.u, hit.v);
    vec4 n0 = vertex_normals[3 * t + 0], n1 = vertex_normals[3 * t + 1],
         n2 = vertex_normals[3 * t + 2];
    vec3 n = w.x * n0.xyz + w.y * n1.xyz + w.z * n2.xyz;
    float len = length(n);
    s.normal = len > 0.0 ? n / len : s.geometric_normal;
    bool flipped = dot(s.normal, s.geometric_normal) < 0.0;
#ifdef HAS_NORMAL_MAP
    // The tangent is interpolated like the normal; the bitangent's sign is the face's
    // (MikkTSpace gives the corners of a face one sign).
    vec4 t0 = unpack_tangent(n0.w);
    vec3 tangent = w.x * t0.xyz + w.y * unpack_tangent(n1.w).xyz + w.z * unpack_tangent(n2.w).xyz;
    s.normal = normal_mapped(s.material, s.normal, vec4(tangent, t0.w), s.uv);
#ifdef HAS_TEXTURES
    s.normal = bump_mapped(s.material, s.normal, s.uv, a.xyz, b.xyz, c.xyz, uv01.xy, uv01.zw, uv2);
#endif
#endif
    // On the geometric normal's side; a normal map tilts it, and shading_at bends it back
    // where it would reflect the view under the surface.
    if (flipped) s.normal = -s.normal;
#else
    s.normal = s.geometric_normal;
#endif
#ifdef GLSLPPM_INSTANCES
    instance_surface_to_world(s, hit.instance);
#endif
    return s;
}

// A new ray's origin, pushed off the surface to the side `dir` leaves on: relative to the
// position's magnitude (ray_offset_floor: a floor relative to the scene size), never absolute.
vec3 offset_origin(vec3 p, vec3 ng, vec3 dir) {
    float m = max(max(abs(p.x), abs(p.y)), max(abs(p.z), ray_offset_floor));
    float eps = m * 3.0e-6;
    return p + (dot(dir, ng) >= 0.0 ? eps : -eps) * ng;
}

Ray make_ray(vec3 origin, vec3 dir) {
    Ray r;
    r.origin = origin;
    r.dir = dir;
    r.tmin = 0.0;
    r.tmax = 3.0e38;
    return r;
}

#endif
