// Test program for common/mtbvh.glsl's walk of a two-level tree (GLSLPPM_INSTANCES;
// tests/native/two_level_probe_test.cpp): per ray, the answers of closest_hit and any_hit and
// the work of closest_hit, so that the test can hold them to native/bvh/traverse_cpu.cpp. Not a pipeline
// stage.
#define BVH_COUNT_VISITS 1
#define GLSLPPM_INSTANCES 1
#include "common/mtbvh.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 3) readonly buffer Rays { vec4 probe_rays[]; };  // (o, tmin), (d, tmax)
// Per ray: (instance, original triangle id, bits of t, any hit), (bits of u, bits of v,
// closest_hit's nodes, its triangles).
layout(std430, binding = 4) writeonly buffer Probe { ivec4 probe_out[]; };

uniform uint u_count;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_count) return;
    vec4 a = probe_rays[2u * i], b = probe_rays[2u * i + 1u];
    Ray r = Ray(a.xyz, b.xyz, a.w, b.w);
    Hit h = closest_hit(r);
    ivec2 work = ivec2(bvh_nodes_visited, bvh_triangles_tested);
    int id = h.triangle < 0 ? -1 : floatBitsToInt(triangles[3 * h.triangle + 1].w);
    int occluded = any_hit(r) ? 1 : 0;
    probe_out[2u * i] = ivec4(h.instance, id, floatBitsToInt(h.t), occluded);
    probe_out[2u * i + 1u] = ivec4(floatBitsToInt(h.u), floatBitsToInt(h.v), work);
}
