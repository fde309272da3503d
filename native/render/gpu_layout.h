// The records the CPU and the GPU stages share, field by field. Each mirrors one GLSL
// declaration, named in its comment, and static_asserts pin every offset, so a field added
// on one side only fails to compile. Binding points come from shaders/common/bindings.glsl,
// and the vec4 records' strides, fields, enums and bits from shaders/common/records.glsl,
// both included here as they are: one list for both sides.
//
// Where things go: a new Frame value is a field here and in shaders/common/frame.glsl; a new
// buffer is a binding in bindings.glsl and a block in the include of its stage group; a new
// material parameter is a field of GpuMaterial here, its vec4 named in records.glsl, and an
// accessor in shaders/common/bsdf.glsl.
#pragma once

#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

#include "common/bindings.glsl"
#include "common/records.glsl"

namespace glslppm {

// `uniform Frame` (shaders/common/frame.glsl, std140): per-pass constants of every stage.
struct FrameBlock {
    glm::mat4 camera_to_world{1.0f};
    glm::mat4 environment_from_world{1.0f};
    glm::vec2 film_half_extent{0.0f};  // on the z = -1 plane, or world units (orthographic)
    glm::vec2 film_shift{0.0f};
    glm::vec3 scene_lo{0.0f};
    float ray_offset_floor = 0.0f;
    glm::vec3 scene_center{0.0f};
    float scene_radius = 0.0f;
    glm::vec3 world_radiance{0.0f};
    std::uint32_t orthographic = 0;
    float aperture_radius = 0.0f;
    float focus_distance = 0.0f;
    std::uint32_t image_width = 0;
    std::uint32_t image_height = 0;
    std::uint32_t photon_threads = 0;
    std::uint32_t hash_cell_count = 0;
    std::uint32_t pass_index = 0;
    std::uint32_t max_bounces = 0;
    std::uint32_t emitter_count = 0;
    float sppm_alpha = 0.0f;
    float radius_floor = 0.0f;
    float inv_passes = 0.0f;
    float inv_photons_emitted = 0.0f;
    std::int32_t environment_texture = -1;
    std::int32_t environment_cdf_width = 0;
    std::int32_t environment_cdf_height = 0;
    float glossy_threshold = 0.0f;  // lobes below this roughness are followed, not gathered
    // The image's place in the whole frame (a render region or a tile): its first pixel's
    // index in the frame, the frame's width and pixel count. The random streams are keyed by
    // the frame's pixel and photon indices, so that a tile draws what the whole frame would.
    std::uint32_t frame_first_pixel = 0;
    std::uint32_t frame_width = 0;
    std::uint32_t frame_pixels = 0;
    // PPPM (ESTIMATOR_PPPM): this pass's radius r_1 s(i), its estimate's factor
    // 1 / (pi r_i^2 N_emitted), and the photon step within the pass (0 starts every path).
    float pass_radius = 0.0f;
    float pass_scale = 0.0f;
    std::uint32_t photon_step = 0;
    std::uint32_t shadow_terminator = 0;  // BumpShadowing: 0 Chiang 2019, 1 Conty 2021
    // Cycles' per-kind limits beside max_bounces (RenderSettings, common/bounces.glsl).
    std::uint32_t max_diffuse_bounces = 0;
    std::uint32_t max_glossy_bounces = 0;
    std::uint32_t max_transmission_bounces = 0;
    // Light tracing's fixed-point unit (common/light_splats.glsl): a splat's value per unit
    // of its 64-bit integer sum.
    float light_splat_unit = 0.0f;
    // Issue 30 (common/light_sampling.glsl, emitter_mis_choice): the probability q of a
    // Lambertian point's BSDF sample of emitters, and the render's seed folded to 32 bits,
    // from which each pass and work group draws whether it takes the sample.
    float emitter_mis_fraction = 1.0f;
    std::uint32_t render_seed = 0;
    std::uint32_t padding[2] = {0, 0};  // std140: the vec4s below start on 16 bytes
    // The light sample's split between the world and the other emitters (render/emitters.h,
    // LightSplit; common/light_sampling.glsl, light_world_share).
    glm::vec4 light_split_centre{0.0f};
    glm::vec4 light_split_power{0.0f};
};
// std140: mat4 and vec3 start on 16 bytes, vec2 on 8; a scalar may fill a vec3's fourth word.
static_assert(offsetof(FrameBlock, environment_from_world) == 64);
static_assert(offsetof(FrameBlock, film_half_extent) == 128);
static_assert(offsetof(FrameBlock, film_shift) == 136);
static_assert(offsetof(FrameBlock, scene_lo) == 144);
static_assert(offsetof(FrameBlock, ray_offset_floor) == 156);
static_assert(offsetof(FrameBlock, scene_center) == 160);
static_assert(offsetof(FrameBlock, scene_radius) == 172);
static_assert(offsetof(FrameBlock, world_radiance) == 176);
static_assert(offsetof(FrameBlock, orthographic) == 188);
static_assert(offsetof(FrameBlock, aperture_radius) == 192);
static_assert(offsetof(FrameBlock, focus_distance) == 196);
static_assert(offsetof(FrameBlock, image_width) == 200);
static_assert(offsetof(FrameBlock, image_height) == 204);
static_assert(offsetof(FrameBlock, photon_threads) == 208);
static_assert(offsetof(FrameBlock, hash_cell_count) == 212);
static_assert(offsetof(FrameBlock, pass_index) == 216);
static_assert(offsetof(FrameBlock, max_bounces) == 220);
static_assert(offsetof(FrameBlock, emitter_count) == 224);
static_assert(offsetof(FrameBlock, sppm_alpha) == 228);
static_assert(offsetof(FrameBlock, radius_floor) == 232);
static_assert(offsetof(FrameBlock, inv_passes) == 236);
static_assert(offsetof(FrameBlock, inv_photons_emitted) == 240);
static_assert(offsetof(FrameBlock, environment_texture) == 244);
static_assert(offsetof(FrameBlock, environment_cdf_width) == 248);
static_assert(offsetof(FrameBlock, environment_cdf_height) == 252);
static_assert(offsetof(FrameBlock, glossy_threshold) == 256);
static_assert(offsetof(FrameBlock, frame_first_pixel) == 260);
static_assert(offsetof(FrameBlock, frame_width) == 264);
static_assert(offsetof(FrameBlock, frame_pixels) == 268);
static_assert(offsetof(FrameBlock, pass_radius) == 272);
static_assert(offsetof(FrameBlock, pass_scale) == 276);
static_assert(offsetof(FrameBlock, photon_step) == 280);
static_assert(offsetof(FrameBlock, shadow_terminator) == 284);
static_assert(offsetof(FrameBlock, max_diffuse_bounces) == 288);
static_assert(offsetof(FrameBlock, max_glossy_bounces) == 292);
static_assert(offsetof(FrameBlock, max_transmission_bounces) == 296);
static_assert(offsetof(FrameBlock, light_splat_unit) == 300);
static_assert(offsetof(FrameBlock, emitter_mis_fraction) == 304);
static_assert(offsetof(FrameBlock, render_seed) == 308);
static_assert(offsetof(FrameBlock, light_split_centre) == 320);
static_assert(offsetof(FrameBlock, light_split_power) == 336);
static_assert(sizeof(FrameBlock) == 352);

// `buffer Counters` (shaders/common/sppm_buffers.glsl, std430): one pass's counts and the
// running 64-bit totals as (lo, hi) words, carried by end_pass.comp.
struct Counters {
    std::uint32_t cell_size_bits;   // hash cell size in use (float bits)
    std::uint32_t max_radius_bits;  // largest radius after the pass (float bits)
    std::uint32_t pass_emitted;     // photon paths started this pass
    std::uint32_t pass_rays;        // rays traced this pass
    std::uint32_t emitted_lo, emitted_hi;
    std::uint32_t rays_lo, rays_hi;
};
static_assert(sizeof(Counters) == 32 && offsetof(Counters, emitted_lo) == 16);

// `buffer PassFilms` (shaders/common/pass_films.glsl, BINDING_PASS_FILMS): vec4 (sum,
// compensation) pairs per enabled render pass and pixel, laid out by PassLayout
// (render/render_passes.h), which also names the offsets' defines.

// `buffer VisiblePoints` (shaders/common/sppm_buffers.glsl): VISIBLE_POINT_VEC4 vec4s per
// pixel, what the gather needs to evaluate the lobes' f(wo, wi)
// (shaders/common/visible_points.glsl names the fields).
inline constexpr std::size_t kVisiblePointVec4 = VISIBLE_POINT_VEC4;

// `buffer Photons` and `buffer PhotonPaths` (shaders/common/sppm_buffers.glsl): vec4s per
// photon thread, the fields named in records.glsl (PHOTON_*, PHOTON_PATH_*).
inline constexpr std::size_t kPhotonBytes = PHOTON_VEC4 * 16;
inline constexpr std::size_t kPhotonPathBytes = PHOTON_PATH_VEC4 * 16;

// `buffer Emitters` (shaders/common/scene_buffers.glsl): one per emitter, then the
// triangles' map (render/emitters.h says what each kind keeps in a, b and c).
struct GpuEmitter {
    glm::vec4 a;      // (v0 or position, the EmitterKind's int bits)
    glm::vec4 b;
    glm::vec4 c;      // (..., cumulative pick probability up to this emitter)
    glm::vec4 power;  // (power rgb, pick probability)
};
static_assert(sizeof(GpuEmitter) == EMITTER_VEC4 * 16 && offsetof(GpuEmitter, a) == EMITTER_A * 16 &&
              offsetof(GpuEmitter, b) == EMITTER_B * 16 && offsetof(GpuEmitter, c) == EMITTER_C * 16 &&
              offsetof(GpuEmitter, power) == EMITTER_POWER * 16);

// `buffer TextureInfo` (shaders/common/textures.glsl, std430): one record per scene texture.
struct GpuTexture {
    glm::ivec4 rect;     // (x, y, width, height) of the image in its atlas layer
    // (layer, float 0/1, TextureWrap | TextureInterpolation << TEXTURE_INTERPOLATION_SHIFT,
    // kTextureFrom*): a Linear texture's third word is its wrap alone.
    glm::ivec4 info;
    // kTextureFromUv: Texture::uv_map_u, w unused; kTextureFromPosition:
    // Texture::position_map_u, over (p, 1).
    glm::vec4 uv_map_u;
    glm::vec4 uv_map_v;
};
inline constexpr int kTextureFromUv = TEXTURE_FROM_UV;
inline constexpr int kTextureFromPosition = TEXTURE_FROM_POSITION;
static_assert(WRAP_MIRROR <= TEXTURE_WRAP_MASK);
static_assert(sizeof(GpuTexture) == 64 && offsetof(GpuTexture, info) == 16 &&
              offsetof(GpuTexture, uv_map_u) == 32 && offsetof(GpuTexture, uv_map_v) == 48);

// Threads of radius_stats.comp: one (sum, max) pair each is read back by stats().
inline constexpr unsigned kRadiusStatsThreads = 256;

// Light tracing's splat buffer per pixel (LIGHT_SPLAT_WORDS uints, common/light_splats.glsl):
// no more than the smallest visible point (3 vec4), which image tiles are planned by.
inline constexpr std::size_t kLightSplatBytes = LIGHT_SPLAT_WORDS * 4;
static_assert(kLightSplatBytes <= 3 * 16);
// The word of a pixel's splats where the float sum (rgb) starts (LIGHT_SPLAT_SUM there).
inline constexpr std::size_t kLightSplatSumWord = 6;

// `buffer Materials` (shaders/common/scene_buffers.glsl), read through the accessors of
// shaders/common/bsdf.glsl and lobes.glsl: MATERIAL_VEC4 per material, then the albedo tables
// (render/microfacet_tables.h) the materials' `table` fields point into.
struct GpuMaterial {
    glm::vec3 color;              // base colour (times its texture)
    float kind;                   // MaterialKind as a float
    glm::vec3 emission;           // radiance
    float ior;                    // dielectric, plastic
    std::int32_t color_texture;   // texture index or -1
    std::uint32_t flags;          // MaterialFlag bits (render/area_lights.h)
    float roughness;
    std::int32_t roughness_texture;
    std::int32_t mix_a, mix_b;    // Mix: the two materials
    float mix_factor;
    std::int32_t mix_texture;
    std::uint32_t options;        // MaterialOption bits and fields below
    float mix_ior;
    std::int32_t table;           // albedo table, as a vec4 index into the buffer, or -1
    std::uint32_t normal_map;     // see normal_map_word
    std::int32_t emission_texture;  // texture index or -1: emission = emission * texel
    glm::vec3 f82_tint;             // Schlick conductor's F82 tint (white: none)
    // Beer-Lambert sigma_a inside the object (Material::absorption; shaders/common/
    // absorption.glsl). Its own vec4, 16 bytes more per material: the five before are full.
    glm::vec3 absorption;
    // Material::light_group + 1 (0: none), common/light_groups.glsl, plus
    // MATERIAL_LINK_ROW_SCALE x Material::light_link_row plus MATERIAL_LINK_SET_SCALE x
    // Material::light_link_set (common/light_linking.glsl)
    float light_group_code;
};
static_assert(sizeof(GpuMaterial) == MATERIAL_VEC4 * 16 &&
              offsetof(GpuMaterial, color) == MATERIAL_COLOR * 16 &&
              offsetof(GpuMaterial, kind) == MATERIAL_COLOR * 16 + 12 &&
              offsetof(GpuMaterial, emission) == MATERIAL_EMISSION * 16 &&
              offsetof(GpuMaterial, ior) == MATERIAL_EMISSION * 16 + 12 &&
              offsetof(GpuMaterial, color_texture) == MATERIAL_TEXTURES * 16 &&
              offsetof(GpuMaterial, flags) == MATERIAL_TEXTURES * 16 + 4 &&
              offsetof(GpuMaterial, roughness) == MATERIAL_TEXTURES * 16 + 8 &&
              offsetof(GpuMaterial, roughness_texture) == MATERIAL_TEXTURES * 16 + 12 &&
              offsetof(GpuMaterial, mix_a) == MATERIAL_MIX_RECORD * 16 &&
              offsetof(GpuMaterial, mix_texture) == MATERIAL_MIX_RECORD * 16 + 12 &&
              offsetof(GpuMaterial, options) == MATERIAL_OPTIONS * 16 &&
              offsetof(GpuMaterial, mix_ior) == MATERIAL_OPTIONS * 16 + 4 &&
              offsetof(GpuMaterial, table) == MATERIAL_OPTIONS * 16 + 8 &&
              offsetof(GpuMaterial, normal_map) == MATERIAL_OPTIONS * 16 + 12 &&
              offsetof(GpuMaterial, emission_texture) == MATERIAL_EMISSION_TEXTURE * 16 &&
              offsetof(GpuMaterial, f82_tint) == MATERIAL_EMISSION_TEXTURE * 16 + 4 &&
              offsetof(GpuMaterial, absorption) == MATERIAL_ABSORPTION * 16);
inline constexpr int kGpuMaterialVec4 = MATERIAL_VEC4;

// GpuMaterial::normal_map: 0 for none, else the normal (or bump) texture's index + 1 in the
// low 15 bits, bit 15 set for a bump map, and the strength as a half float in the high 16
// (GLSL's unpackHalf2x16; 11 bits of precision: strength 0.3 reads 0.29988). A bump map's
// distance is a half float in the options' high 16 bits. Read by shaders/common/surface.glsl.
inline constexpr std::uint32_t kMaxNormalMapTextures = 0x7FFFu;
inline constexpr std::uint32_t kNormalMapBump = 0x8000u;
inline constexpr std::uint32_t kOptionBumpDistanceShift = OPTION_BUMP_DISTANCE_SHIFT;

// GpuMaterial::options (the OPTION_ bits of shaders/common/records.glsl).
inline constexpr std::uint32_t kOptionMixChannelShift = OPTION_MIX_CHANNEL_SHIFT;
inline constexpr std::uint32_t kOptionMixModeShift = OPTION_MIX_MODE_SHIFT;
inline constexpr std::uint32_t kOptionMultiscatter = OPTION_MULTISCATTER;
inline constexpr std::uint32_t kOptionSchlick = OPTION_SCHLICK;
inline constexpr std::uint32_t kOptionTintReflection = OPTION_TINT_REFLECTION;

}  // namespace glslppm
