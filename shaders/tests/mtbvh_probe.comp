// Test program for common/mtbvh.glsl (tests/native/mtbvh_probe_test.cpp): per ray, the link
// set the shared traversal picks (the one eye_trace and photon_trace use) and, with
// BVH_COUNT_VISITS, the answers and the work of closest_hit and any_hit, so that the test
// can hold them to native/bvh/traverse_cpu.cpp exactly. Not a pipeline stage. Define
// GLSLPPM_TBVH for a single-order BVH, as the renderer's programs would.
#define BVH_COUNT_VISITS 1
#include "common/mtbvh.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 3) readonly buffer Rays { vec4 probe_rays[]; };  // (o, tmin), (d, tmax)
// Per ray: (order, link base, closest hit's original id, any hit), then (closest_hit's
// nodes, its triangles, any_hit's nodes, its triangles); traced only when u_trace != 0, so
// that the order alone can be probed without a BVH.
layout(std430, binding = 4) writeonly buffer Probe { ivec4 probe_out[]; };

uniform uint u_count;
uniform uint u_trace;

// Original triangle id of a packed index, -1 for a miss (what the CPU traversal returns).
int probe_original_id(int packed_index) {
    return packed_index < 0 ? -1 : floatBitsToInt(triangles[3 * packed_index + 1].w);
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_count) return;
    vec4 a = probe_rays[2u * i], b = probe_rays[2u * i + 1u];
    Ray r = Ray(a.xyz, b.xyz, a.w, b.w);
    int closest = -1, occluded = 0;
    ivec4 work = ivec4(0);
    if (u_trace != 0u) {
        closest = probe_original_id(closest_hit(r).triangle);
        work.xy = ivec2(bvh_nodes_visited, bvh_triangles_tested);
        bvh_nodes_visited = 0u;
        bvh_triangles_tested = 0u;
        occluded = any_hit(r) ? 1 : 0;
        work.zw = ivec2(bvh_nodes_visited, bvh_triangles_tested);
    }
    probe_out[2u * i] = ivec4(bvh_select_order(r.dir), bvh_link_base(r.dir), closest, occluded);
    probe_out[2u * i + 1u] = work;
}
