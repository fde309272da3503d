// Scene data beside the MTBVH (its records in common/records.glsl).
#ifndef SCENE_BUFFERS_GLSL
#define SCENE_BUFFERS_GLSL
#include "common/bindings.glsl"
#include "common/records.glsl"

// Lights photons start from, EMITTER_VEC4 per emitter (common/records.glsl names the fields;
// native/render/emitters.h says what each kind keeps in them).
#ifdef USES_EMITTERS
layout(std430, binding = BINDING_EMITTERS) readonly buffer Emitters { vec4 emitters[]; };
vec4 emitter_record(uint k, uint field) { return emitters[EMITTER_VEC4 * k + field]; }
int emitter_kind(uint k) {
    return floatBitsToInt(emitter_record(k, EMITTER_A).w) & EMITTER_KIND_MASK;
}
// The emitter's light group code (common/light_groups.glsl): its group + 1, 0 for none.
uint emitter_group_code(uint k) {
    return (uint(floatBitsToInt(emitter_record(k, EMITTER_A).w)) >> EMITTER_GROUP_SHIFT) & 255u;
}
// The emitter's light link set (common/light_linking.glsl; 0 without links).
uint emitter_link_set(uint k) {
    return uint(floatBitsToInt(emitter_record(k, EMITTER_A).w)) >> EMITTER_LINK_SHIFT;
}
#endif

// Materials, MATERIAL_VEC4 each (GpuMaterial in native/render/gpu_layout.h), then albedo
// tables; their accessors are in common/bsdf.glsl, common/lobes.glsl and
// common/absorption.glsl.
layout(std430, binding = BINDING_MATERIALS) readonly buffer Materials { vec4 materials[]; };
vec4 material_record(int m, int field) { return materials[MATERIAL_VEC4 * m + field]; }

#ifdef HAS_NORMALS
// Vertex normals, 3 per packed triangle (n.xyz, 0), or (n.xyz, packed tangent) where normal
// maps need tangents (HAS_NORMAL_MAP; native/scene/tangent_space.h).
layout(std430, binding = BINDING_NORMALS) readonly buffer Normals { vec4 vertex_normals[]; };
#endif

#ifdef HAS_TEXTURES
// Texture coordinates, 2 per packed triangle: (uv0, uv1), (uv2, 0, 0).
layout(std430, binding = BINDING_UVS) readonly buffer Uvs { vec4 vertex_uvs[]; };
#endif

#ifdef HAS_VERTEX_COLORS
// Linear vertex colours, 3 per packed triangle: (c.rgb, 0) (native/bvh/packed_bvh.h).
layout(std430, binding = BINDING_VERTEX_COLORS) readonly buffer VertexColors { vec4 vertex_colors[]; };
#endif

#endif
