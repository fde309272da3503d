// Deformation motion blur on the GPU (docs/motion_blur.md; native/render/motion_pass.cpp
// dispatches it): a deforming mesh's packed triangles, their vertex normals and its bottom
// tree's boxes at the pass's time, where the host used to write them and upload them every
// pass. The steps' positions and normals and the tables below are uploaded once.
// PHASE_VERTICES, one thread per packed triangle of one mesh: its corners (and normals)
//   interpolated between the two motion steps around the time (DeformMotion::segment).
// PHASE_REFIT, one thread per node of one depth (the deepest first, over every deforming
//   mesh): a leaf's box holds its triangles, padded as the build pads it (bvh/aabb.h,
//   pad_box); an inner node's is the union of its children's. The topology built at the
//   frame's time stays.
layout(local_size_x = LOCAL_SIZE) in;

#include "common/frame.glsl"

layout(std430, binding = BINDING_BVH_NODES) buffer BvhNodes { vec4 bvh_nodes[]; };
layout(std430, binding = BINDING_TRIANGLES) buffer Triangles { vec4 triangles[]; };

#if defined(PHASE_VERTICES)
layout(std430, binding = BINDING_NORMALS) buffer Normals { vec4 vertex_normals[]; };
// Every deforming mesh's vertices at every step, one vec4 each (w unused).
layout(std430, binding = BINDING_DEFORM_POSITIONS) readonly buffer DeformPositions {
    vec4 deform_positions[];
};
layout(std430, binding = BINDING_DEFORM_NORMALS) readonly buffer DeformNormals {
    vec4 deform_normals[];
};
// Per packed triangle of a deforming mesh: (its index in `triangles`, its three vertices).
layout(std430, binding = BINDING_DEFORM_TRIANGLES) readonly buffer DeformTriangles {
    uvec4 deform_triangles[];
};
uniform uint u_first;     // this mesh's first entry in deform_triangles
uniform uint u_count;     // and its entries
uniform uint u_step_a;    // the first of the two steps' vertices in deform_positions
uniform uint u_step_b;
uniform float u_blend;    // how far between them
uniform uint u_normals;   // 1: the mesh has vertex normals

void main() {
    uint k = thread_index();
    if (k >= u_count) return;
    uvec4 entry = deform_triangles[u_first + k];
    for (uint c = 0u; c < 3u; ++c) {
        uint v = entry[1u + c];
        vec3 a = deform_positions[u_step_a + v].xyz, b = deform_positions[u_step_b + v].xyz;
        // As the host's lerp: no fused multiply-add, so that llvmpipe matches it exactly.
        precise vec3 p = a + u_blend * (b - a);
        uint slot = 3u * entry.x + c;
        triangles[slot] = vec4(p, triangles[slot].w);
        if (u_normals == 0u) continue;
        vec3 na = deform_normals[u_step_a + v].xyz, nb = deform_normals[u_step_b + v].xyz;
        precise vec3 m = na + u_blend * (nb - na);
        float len = length(m);
        vertex_normals[slot] = vec4(len > 0.0 ? m / len : na, vertex_normals[slot].w);
    }
}

#elif defined(PHASE_REFIT)
// Per node, deepest first: (node, left child, right child, 0); children -1 at a leaf.
layout(std430, binding = BINDING_DEFORM_REFIT) readonly buffer DeformRefit {
    ivec4 deform_refit[];
};
uniform uint u_first;  // this depth's first entry
uniform uint u_count;

const float BOX_PAD_RELATIVE = 1.0 / 524288.0;  // bvh/aabb.h, kBoxPadRelative

void main() {
    uint k = thread_index();
    if (k >= u_count) return;
    ivec4 entry = deform_refit[u_first + k];
    int node = entry.x;
    vec3 lo, hi;
    if (entry.y < 0) {
        int first = floatBitsToInt(bvh_nodes[2 * node].w);
        int count = floatBitsToInt(bvh_nodes[2 * node + 1].w);
        lo = vec3(uintBitsToFloat(0x7F800000u));  // +infinity
        hi = -lo;
        for (int i = first; i < first + count; ++i)
            for (int c = 0; c < 3; ++c) {
                vec3 v = triangles[3 * i + c].xyz;
                lo = min(lo, v);
                hi = max(hi, v);
            }
        vec3 m = max(abs(lo), abs(hi));
        float pad = max(m.x, max(m.y, m.z)) * BOX_PAD_RELATIVE;
        lo -= pad;
        hi += pad;
    } else {
        lo = min(bvh_nodes[2 * entry.y].xyz, bvh_nodes[2 * entry.z].xyz);
        hi = max(bvh_nodes[2 * entry.y + 1].xyz, bvh_nodes[2 * entry.z + 1].xyz);
    }
    bvh_nodes[2 * node] = vec4(lo, bvh_nodes[2 * node].w);
    bvh_nodes[2 * node + 1] = vec4(hi, bvh_nodes[2 * node + 1].w);
}
#endif
