// The records the GPU stages read from plain vec4 buffers, and the enums and bit fields
// inside them: one list for the shaders and the C++, as bindings.glsl is for the binding
// points. native/render/gpu_layout.h includes this file as it is and pins the C++ structs'
// offsets to it with static_asserts; the C++ enums take their values from it. So it holds
// nothing but #defines and comments (valid GLSL and valid C++ alike), and a stride, field,
// enum value or bit is typed here and nowhere else.
//
// A field is named by its vec4's index within the record; the comment says what each
// component holds. Stages read a record's vec4s through the accessors of its include, one
// vec4 at a time where they need only part of it.
#ifndef GLSLPPM_RECORDS_GLSL
#define GLSLPPM_RECORDS_GLSL

// --- Materials (GpuMaterial; accessors in common/bsdf.glsl and common/lobes.glsl) ---
// MATERIAL_VEC4 vec4s per material, then the albedo tables the `table` field points into.
#define MATERIAL_VEC4 7
#define MATERIAL_COLOR 0             // (colour rgb, kind)
#define MATERIAL_EMISSION 1          // (emitted radiance rgb, ior)
#define MATERIAL_TEXTURES 2          // (colour texture, flags, roughness, roughness texture)
#define MATERIAL_MIX_RECORD 3        // (mix a, mix b, mix factor, mix factor's texture)
#define MATERIAL_OPTIONS 4           // (options, mix ior, albedo table, normal map word)
#define MATERIAL_EMISSION_TEXTURE 5  // (emission texture, F82 tint rgb)
#define MATERIAL_ABSORPTION 6        // (sigma_a rgb, link word: group code + 64 link row)

// MaterialKind (native/scene/scene.h): the `kind` field.
#define MATERIAL_DIFFUSE 0
#define MATERIAL_CONDUCTOR 1
#define MATERIAL_DIELECTRIC 2
#define MATERIAL_PLASTIC 3
#define MATERIAL_TRANSLUCENT 4
#define MATERIAL_TRANSPARENT 5
#define MATERIAL_MIX 6

// MaterialFlag (native/render/area_lights.h): the `flags` field's bits.
#define MATERIAL_LIGHT_SURFACE 1            // rays add its emission and pass through it
#define MATERIAL_HIDDEN_FROM_CAMERA 2       // camera rays pass it without its emission
#define MATERIAL_ONE_SIDED_EMISSION 4       // emits from its front face only
#define MATERIAL_CASTS_NO_SHADOW 8          // photons and shadow rays pass through
#define MATERIAL_MAY_BE_TRANSPARENT 16      // a Mix with a Transparent leaf
#define MATERIAL_HIDDEN_FROM_REFLECTIONS 32 // eye rays after a bounce pass it
#define MATERIAL_VERTEX_COLOR 64            // its colour times the hit's vertex colour

// The `options` field: bits 0-2 the roughness texture's TextureChannel, 4-6 the mix
// factor's, 8-9 the MixFactor, the flags below, and from bit 16 a bump map's distance (a
// half float; the normal map word is described in gpu_layout.h).
#define OPTION_ROUGHNESS_CHANNEL 7u
#define OPTION_MIX_CHANNEL_SHIFT 4u
#define OPTION_MIX_MODE_SHIFT 8u
#define OPTION_MULTISCATTER 4096u      // energy compensation on
#define OPTION_SCHLICK 8192u           // conductor: Schlick Fresnel from the colour
#define OPTION_TINT_REFLECTION 16384u  // dielectric: the colour tints reflection too
#define OPTION_BUMP_DISTANCE_SHIFT 16u

// MixFactor (native/scene/scene.h): what a Mix's factor is.
#define MIX_FACTOR_CONSTANT 0u
#define MIX_FACTOR_FRESNEL 1u
#define MIX_FACTOR_FACING 2u
#define MIX_FACTOR_LAYER_FRESNEL 3u

// TextureChannel (native/scene/scene.h): which number of a texel a scalar input reads.
#define TEXTURE_CHANNEL_RED 0u
#define TEXTURE_CHANNEL_GREEN 1u
#define TEXTURE_CHANNEL_BLUE 2u
#define TEXTURE_CHANNEL_ALPHA 3u
#define TEXTURE_CHANNEL_LUMINANCE 4u

// How deep Mix materials may nest (the stages walk down at most this many levels).
#define MAX_MIX_DEPTH 8
// The albedo tables' grid (native/render/microfacet_tables.h, common/lobes.glsl).
#define ALBEDO_TABLE_SIZE 32

// --- Textures (GpuTexture; common/textures.glsl) ---
// TextureWrap (native/scene/scene.h): Blender's Image Texture extensions.
#define WRAP_REPEAT 0
#define WRAP_CLIP 1
#define WRAP_EXTEND 2
#define WRAP_MIRROR 3
// TextureInterpolation (native/scene/scene.h): the Image Texture's interpolation. GpuTexture's
// info.z holds the wrap in its low bits and the interpolation from this shift, so that a
// Linear texture's word is its wrap as before.
#define INTERPOLATION_LINEAR 0
#define INTERPOLATION_CLOSEST 1
#define TEXTURE_WRAP_MASK 255
#define TEXTURE_INTERPOLATION_SHIFT 8
// Where a texture is looked up from: the mesh's uv, or the world position.
#define TEXTURE_FROM_UV 0
#define TEXTURE_FROM_POSITION 1

// --- Emitters (native/render/emitters.h; common/emitters.glsl, light_sampling.glsl) ---
// EMITTER_VEC4 vec4s per emitter, then (with emitter MIS) the triangles' map.
#define EMITTER_VEC4 4
#define EMITTER_A 0      // (v0 or position, kind as int bits)
#define EMITTER_B 1      // (v1, two-sided) / (0, radius) / (spot axis, cos half angle) / ...
#define EMITTER_C 2      // (v2 or spot's (smooth width, radius, falloff), cumulative pick)
#define EMITTER_POWER 3  // (power rgb, pick probability)
// EMITTER_A's w holds the kind's int bits in its low byte and, from EMITTER_GROUP_SHIFT, the
// emitter's light group code (common/light_groups.glsl: the group + 1, 0 for none).
// From EMITTER_LINK_SHIFT, its light link set (common/light_linking.glsl).
#define EMITTER_KIND_MASK 255
#define EMITTER_GROUP_SHIFT 8
#define EMITTER_LINK_SHIFT 16
// EmitterKind.
#define EMITTER_TRIANGLE 0
#define EMITTER_POINT 1
#define EMITTER_SPOT 2
#define EMITTER_SUN 3
#define EMITTER_ENVIRONMENT 4

// --- Photons stored by a pass (photon_trace.comp; read by hash_photons.comp, gather.comp) ---
#define PHOTON_VEC4 3
#define PHOTON_POSITION 0  // (position, hash key: a random number in (0, 1))
#define PHOTON_INCOMING 1  // (direction it came from, record word: class and bounces)
#define PHOTON_FLUX 2      // (flux rgb or 0 for none, side word)

// --- Photon paths in flight, path regeneration (photon_trace.comp, restart_film.comp) ---
#define PHOTON_PATH_VEC4 3
#define PHOTON_PATH_ORIGIN 0  // (origin, bounces so far or -1 to start anew from a light)
#define PHOTON_PATH_DIR 1     // (direction, bounce word)
#define PHOTON_PATH_FLUX 2    // (flux rgb, path class)

// --- Light groups (common/light_groups.glsl, docs/light_groups.md) ---
// A group's code is its index + 1 (0: no group); the stored photon's record word keeps it in
// 6 bits, so a scene has at most this many groups.
#define MAX_LIGHT_GROUPS 63

// --- Light linking (common/light_linking.glsl, docs/light_linking.md) ---
// A link set is a bit of a row's masks; a material's row rides above its group code in
// MATERIAL_ABSORPTION's w (times MATERIAL_LINK_ROW_SCALE), and the link set of its emission
// above the row (times MATERIAL_LINK_SET_SCALE): below 2^19, exact in a float.
#define MAX_LIGHT_LINK_SETS 32
#define MAX_LIGHT_LINK_ROWS 256
#define MATERIAL_LINK_ROW_SCALE 64
#define MATERIAL_LINK_SET_SCALE 16384  // MATERIAL_LINK_ROW_SCALE x MAX_LIGHT_LINK_ROWS

// --- Visible points, one per pixel (common/visible_points.glsl names the fields) ---
#define VISIBLE_POINT_VEC4 4u

// --- Light tracing's splats per pixel (common/light_splats.glsl) ---
#define LIGHT_SPLAT_WORDS 12u

#endif
