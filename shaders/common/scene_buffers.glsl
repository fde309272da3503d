// Scene data beside the MTBVH (mirrored in native/render/gpu_layout.h).
#ifndef SCENE_BUFFERS_GLSL
#define SCENE_BUFFERS_GLSL
#include "common/bindings.glsl"

// Lights photons start from, 4 per emitter: (a.xyz, kind), (b.xyz, b.w), (c.xyz, cumulative
// pick probability), (power or radiance rgb, pick probability). See native/render/emitters.h.
#ifdef USES_EMITTERS
layout(std430, binding = BINDING_EMITTERS) readonly buffer Emitters { vec4 emitters[]; };
#endif

// Materials, 7 vec4 each (GpuMaterial in native/render/gpu_layout.h), then albedo tables;
// their accessors are in common/bsdf.glsl, common/lobes.glsl and common/absorption.glsl.
layout(std430, binding = BINDING_MATERIALS) readonly buffer Materials { vec4 materials[]; };
const int MATERIAL_STRIDE = 7;

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

const int MATERIAL_DIFFUSE = 0;
const int MATERIAL_CONDUCTOR = 1;
const int MATERIAL_DIELECTRIC = 2;
const int MATERIAL_PLASTIC = 3;
const int MATERIAL_TRANSLUCENT = 4;
const int MATERIAL_TRANSPARENT = 5;
const int MATERIAL_MIX = 6;

const int EMITTER_TRIANGLE = 0;
const int EMITTER_POINT = 1;
const int EMITTER_SPOT = 2;
const int EMITTER_SUN = 3;
const int EMITTER_ENVIRONMENT = 4;

#endif
