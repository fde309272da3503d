// What a ray hit: position, normals and material, read from the packed MTBVH triangles.
#ifndef SURFACE_GLSL
#define SURFACE_GLSL

#include "common/mtbvh.glsl"
#include "common/scene_buffers.glsl"

// The unit normal of a triangle's winding. The edges are scaled by their largest component
// first: the cross product squares them, which overflows or underflows a float for
// triangles far larger or smaller than unit size.
vec3 triangle_normal(vec3 a, vec3 b, vec3 c) {
    vec3 e1 = b - a, e2 = c - a;
    float m = max(max(max(abs(e1.x), abs(e1.y)), max(abs(e1.z), abs(e2.x))),
                  max(abs(e2.y), abs(e2.z)));
    return normalize(cross(e1 / m, e2 / m));
}

struct Surface {
    vec3 position;
    vec3 geometric_normal;  // from the winding: emitters face this way
    vec3 normal;            // shading normal, on the same side as the geometric one
    int material;
    vec2 uv;                // texture coordinates (HAS_TEXTURES only)
};

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
#ifdef HAS_NORMALS
    vec3 n = (1.0 - hit.u - hit.v) * vertex_normals[3 * t + 0].xyz +
             hit.u * vertex_normals[3 * t + 1].xyz + hit.v * vertex_normals[3 * t + 2].xyz;
    float len = length(n);
    s.normal = len > 0.0 ? n / len : s.geometric_normal;
    if (dot(s.normal, s.geometric_normal) < 0.0) s.normal = -s.normal;
#else
    s.normal = s.geometric_normal;
#endif
    s.material = floatBitsToInt(a.w);
#ifdef HAS_TEXTURES
    vec4 uv01 = vertex_uvs[2 * t + 0];
    vec2 uv2 = vertex_uvs[2 * t + 1].xy;
    s.uv = (1.0 - hit.u - hit.v) * uv01.xy + hit.u * uv01.zw + hit.v * uv2;
#else
    s.uv = vec2(0.0);
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
