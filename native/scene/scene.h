// The scene as the renderer takes it: world-space triangles (a MeshView whose arrays the
// caller keeps alive), the material table, lights, camera and environment. The add-on, the
// loaders and the procedural scenes all fill this one struct.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "common/records.glsl"  // the enums' values, shared with the shaders
#include "scene/mesh.h"
#include "scene/motion.h"

namespace glslppm {

// The material model (DESIGN.md): every Blender material maps onto these lobes, mixed.
//   Diffuse      Lambert.
//   Conductor    GGX microfacet metal reflecting `color` (Glossy), or Schlick's Fresnel from
//                it (`schlick`: Principled's metal); roughness 0 is a mirror.
//   Dielectric   GGX rough glass (reflection and refraction, Walter et al. 2007); roughness 0
//                is smooth glass. `color` tints the transmitted light (and the reflected
//                light too with `tint_reflection`, as the Glass BSDF node does).
//   Plastic      a GGX dielectric layer of index `ior` over a Lambert base of `color`
//                (Fresnel-weighted, energy-conserving), as Principled's non-metallic part.
//   Translucent  Lambert transmission to the other side.
//   Transparent  passes light straight through, tinted by `color` (alpha cut-outs).
//   Mix          chooses material mix_b with probability mix_factor, else mix_a (Blender's
//                Mix Shader, Fac 0 = first); the leaves are whole materials of the table.
// How deep Mix materials may nest (the GPU walks down at most this many levels).
inline constexpr int kMaxMixDepth = MAX_MIX_DEPTH;

enum class MaterialKind : std::uint32_t {
    Diffuse = MATERIAL_DIFFUSE,
    Conductor = MATERIAL_CONDUCTOR,
    Dielectric = MATERIAL_DIELECTRIC,
    Plastic = MATERIAL_PLASTIC,
    Translucent = MATERIAL_TRANSLUCENT,
    Transparent = MATERIAL_TRANSPARENT,
    Mix = MATERIAL_MIX,
};

// What a Mix's factor is: a constant (times its texture), Fresnel of index mix_ior at the
// view direction (Blender's Fresnel node, whose index is inverted on back faces), Layer
// Weight's facing output with blend mix_ior, or the Fresnel of a BSDF's own reflective layer
// (Principled's specular and coat, glTF's clearcoat): index mix_ior on both sides, as Cycles
// sets up those layers (never inverted, so never total internal reflection from behind).
enum class MixFactor : std::uint32_t {
    Constant = MIX_FACTOR_CONSTANT,
    Fresnel = MIX_FACTOR_FRESNEL,
    Facing = MIX_FACTOR_FACING,
    LayerFresnel = MIX_FACTOR_LAYER_FRESNEL,
};

// Which number of a texel a scalar input reads: Blender's colour-to-float conversion is the
// luminance (Rec. 709 weights); glTF's metallicRoughness reads green and blue.
enum class TextureChannel : std::uint32_t {
    Red = TEXTURE_CHANNEL_RED,
    Green = TEXTURE_CHANNEL_GREEN,
    Blue = TEXTURE_CHANNEL_BLUE,
    Alpha = TEXTURE_CHANNEL_ALPHA,
    Luminance = TEXTURE_CHANNEL_LUMINANCE,
};

struct Material {
    MaterialKind kind = MaterialKind::Diffuse;
    glm::vec3 color{0.8f};     // albedo (diffuse), reflectance (conductor), tint (dielectric)
    float ior = 1.5f;          // dielectric only
    glm::vec3 emission{0.0f};  // emitted radiance
    std::int32_t color_texture = -1;  // index into Scene::textures: colour = color * texel
    // Blender's meshes emit from both faces (Cycles); false: from the front face only, along
    // the winding's normal (the built-in scenes' emissive ceilings, single-sided glTF materials).
    bool emission_two_sided = true;
    // Blender's ray visibility: camera rays pass through surfaces not visible to the camera;
    // photons pass through (depositing on diffuse ones) surfaces that cast no shadow.
    bool visible_to_camera = true;
    bool casts_shadow = true;
    // Eye rays after a bounce (reflected or refracted) pass through it when false. With
    // visible_to_camera false too no eye path sees the surface: the original glslppm's
    // emitters, which its rays never hit (MtlConvention::Glslppm2015).
    bool visible_in_reflections = true;
    // Microfacet lobes (conductor, dielectric, plastic's layer): Blender's roughness, GGX
    // alpha = roughness^2, times the texture's channel where there is one.
    float roughness = 0.0f;
    std::int32_t roughness_texture = -1;
    TextureChannel roughness_channel = TextureChannel::Luminance;
    // Energy lost to single scattering restored (Blender's "Multiscatter GGX"); false is
    // plain single-scatter GGX ("GGX").
    bool multiscatter = true;
    bool schlick = false;          // conductor
    // Schlick conductor: Blender 4.x's F82 tint (Principled v2 metal's Specular Tint), the
    // reflectance at about 82 degrees as Schlick's times this colour; white leaves Schlick.
    glm::vec3 f82_tint{1.0f};
    bool tint_reflection = false;  // dielectric
    // Mix only: the two materials (indices into the table) and the factor.
    std::int32_t mix_a = -1;
    std::int32_t mix_b = -1;
    float mix_factor = 0.5f;
    std::int32_t mix_texture = -1;
    TextureChannel mix_channel = TextureChannel::Luminance;
    MixFactor mix_mode = MixFactor::Constant;
    float mix_ior = 1.5f;  // Fresnel's index, or Layer Weight's blend
    // Blender's Normal Map node in tangent space (glTF's normalTexture): the texel's rgb
    // (linear, 2 rgb - 1) in the vertex's (tangent, bitangent, normal) frame, blended with
    // the interpolated normal by `normal_strength` as Blender blends it. Read on the
    // triangle's own material (a Mix's root): it applies to all the Mix's leaves.
    std::int32_t normal_texture = -1;
    float normal_strength = 1.0f;
    // Blender's Bump node with an image's luminance as its Height: the normal tilts against
    // the height's gradient on the surface (from finite differences of the texture in uv),
    // normalize(n - distance grad h), blended with n by the strength, as Cycles computes it.
    // A negative distance is Blender's Invert. Not together with a normal map.
    std::int32_t bump_texture = -1;
    float bump_strength = 1.0f;
    float bump_distance = 1.0f;
    // Emission colour from an image: radiance = emission * texel (Blender's Emission node
    // or Principled's Emission Color fed by an Image Texture, glTF's emissiveTexture). Read
    // on the triangle's own material (a Mix's root), like the normal map.
    std::int32_t emission_texture = -1;
    // The colour (base, diffuse, glossy, glass: every lobe's colour, not the emission) times
    // the mesh's per-vertex colour interpolated at the hit (MeshView::colors; white where a
    // mesh has none): Blender's Color Attribute node, glTF's COLOR_0.
    bool vertex_color = false;
    // Homogeneous absorption inside a closed object (Blender's Volume Absorption, glTF's
    // KHR_materials_volume): sigma_a per RGB, per unit of world length; light that runs a
    // length t inside keeps exp(-sigma_a t) (Beer-Lambert). Read on the triangle's own
    // material (a Mix's root) when a ray leaves through its back face; zero: none.
    glm::vec3 absorption{0.0f};
    // Blender's light group of the objects that emit with this material (Scene::light_groups;
    // -1: none). Emission is per material here, so the add-on gives an emissive material
    // shared by objects of different groups one copy per group.
    std::int32_t light_group = -1;
    // Light linking (Blender 4.0+'s Light Linking and Shadow Linking; docs/light_linking.md):
    // the link set of the emitters that emit with this material (0 ... 31), and the row of
    // Scene::light_link_receives / shadow_link_blocks that says which link sets reach this
    // material and which it shadows. Both 0 where a scene has no links.
    std::int32_t light_link_set = 0;
    std::int32_t light_link_row = 0;
};

// Blender's Image Texture extensions, as Cycles reads texels outside the image: Repeat wraps,
// Clip reads transparent black, Extend the nearest edge texel, Mirror reflects at each edge.
enum class TextureWrap : std::uint32_t {
    Repeat = WRAP_REPEAT,
    Clip = WRAP_CLIP,
    Extend = WRAP_EXTEND,
    Mirror = WRAP_MIRROR,
};

// Blender's Image Texture interpolation: Linear filters between the four nearest texel
// centres, Closest reads the one texel the point falls in (Cycles' interp_closest). Cubic and
// Smart (Cycles' cubic B-spline) are rendered as Linear by the add-on, with a warning.
enum class TextureInterpolation : std::uint32_t {
    Linear = INTERPOLATION_LINEAR,
    Closest = INTERPOLATION_CLOSEST,
};

// An RGBA image. Texel (x, y) covers uv ([x, x+1] / width, [y, y+1] / height): row 0 is the
// bottom row (v = 0), as in Blender's pixel arrays. Exactly one of `srgb8` (8-bit, sRGB
// encoded, decoded to linear by the renderer) and `linear` (float, linear) holds
// width * height * 4 values.
struct Texture {
    std::string name;  // for messages: the file or image it came from
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> srgb8;
    std::vector<float> linear;
    TextureWrap wrap = TextureWrap::Repeat;
    TextureInterpolation interpolation = TextureInterpolation::Linear;
    // Where the image is looked up for a surface point of mesh uv (u, v): at
    // (dot(uv_map_u, (u, v, 1)), dot(uv_map_v, (u, v, 1))), a 2-D affine map (Blender's
    // Mapping and Vector Math nodes between the UV output and the Image Texture's Vector;
    // export/texture_mapping.py). Textures that differ only here share one copy of the pixels
    // on the GPU.
    glm::vec3 uv_map_u{1.0f, 0.0f, 0.0f};
    glm::vec3 uv_map_v{0.0f, 1.0f, 0.0f};
    // Or, with from_position, at (dot(position_map_u, (p, 1)), dot(position_map_v, (p, 1)))
    // for the surface point's world position p, uv_map unused: Blender's Generated and
    // Object coordinates, the object's inverse transform and texture space folded in by the
    // add-on (export/texture_mapping.py; docs/texture_coordinates.md).
    bool from_position = false;
    glm::vec4 position_map_u{0.0f};
    glm::vec4 position_map_v{0.0f};
};

// Lights use Blender's units, so that the add-on hands them over unchanged:
// point and spot: power in watts (radiant intensity power / (4 pi) W/sr, spots not
// concentrated into their cone, as in Cycles); sun: strength = irradiance in W/m^2;
// area: power in watts, radiance power / (pi * area) over one side (Cycles 4.x; Blender 3.x
// lights are converted by the add-on).
enum class LightKind : std::uint32_t { Point = 0, Spot = 1, Sun = 2, Area = 3 };
enum class AreaShape : std::uint32_t { Square = 0, Rectangle = 1, Disk = 2, Ellipse = 3 };

struct Light {
    LightKind kind = LightKind::Point;
    glm::vec3 color{1.0f};
    float power = 1.0f;
    glm::vec3 position{0.0f};
    glm::vec3 direction{0.0f, 0.0f, -1.0f};  // the direction light travels (spot, sun)
    float spot_size = 0.785398f;             // full cone angle, radians (Blender's spot_size)
    float spot_blend = 0.15f;                // Blender's spot_blend
    float radius = 0.0f;  // point/spot: radius of the emitting sphere (Blender's soft size)
    float angle = 0.0f;   // sun: angular diameter, radians
    bool spot_cosine = false;  // Blender 3.x: the spot's intensity also falls with cos(angle)
    // Point and spot lights of a radius as Cycles lights them by default (3.x always; 4.x and
    // later while the light's Soft Falloff is on): from a disc of that radius facing the lit
    // point (irradiance d^2 / (d^2 + r^2) of the sphere's on its axis). False: the sphere
    // (Cycles 4.x and later with Soft Falloff off).
    bool facing_disc = false;
    // Area: the light's frame (its origin is the centre; it emits along local -Z from the
    // shape in its XY plane, sizes being full extents; square and disk use size_x for both).
    glm::mat4 to_world{1.0f};
    AreaShape shape = AreaShape::Square;
    float size_x = 1.0f;
    float size_y = 1.0f;
    bool visible_to_camera = true;  // area: seen by camera rays (and specular chains)
    std::int32_t light_group = -1;  // index into Scene::light_groups, -1: none
    std::int32_t light_link_set = 0;  // its link set (Scene::light_link_receives' bits)
};

enum class Projection : std::uint32_t { Perspective = 0, Orthographic = 1 };

// Looks down its local -Z with +Y up, as a Blender camera does.
struct Camera {
    glm::mat4 to_world{1.0f};
    float fov_x = 0.691111f;  // full horizontal angle of view, radians (Blender's 50 mm lens)
    float shift_x = 0.0f;     // Blender's shift: fraction of the larger image dimension
    float shift_y = 0.0f;
    Projection projection = Projection::Perspective;
    float ortho_scale = 6.0f;
    float aperture_radius = 0.0f;
    float focus_distance = 10.0f;
    // A pixel's height over its width (Blender's pixel aspect y / x): the film spans
    // width : height x pixel_aspect; 1 for square pixels.
    float pixel_aspect = 1.0f;
    // A window of a larger frame (Blender's render region): the frame's full size in pixels
    // and the window's top-left pixel in it; the window is the image's own size.
    // full_width 0: the image is the whole frame.
    int full_width = 0;
    int full_height = 0;
    int region_x = 0;
    int region_y = 0;
};

struct Scene {
    MeshView mesh;  // world-space triangles, placed once
    std::shared_ptr<const void> keepalive;  // owns the arrays the MeshViews point into
    // Instanced geometry: meshes in their own space, each placed by any number of instances
    // (Instance::mesh indexes instance_meshes). The renderer traces them through a two-level
    // MTBVH, or flattens them into world space where that is faster (RenderSettings::
    // instancing, stats()["instancing"]).
    std::vector<MeshView> instance_meshes;
    std::vector<Instance> instances;
    std::vector<Material> materials;
    std::vector<Light> lights;
    Camera camera;
    std::vector<Texture> textures;
    glm::vec3 environment{0.0f};  // radiance of the world (multiplies the map when there is one)
    // An equirectangular map (index into textures, -1 for none) in Blender's (Cycles')
    // mapping: in the map's frame, +Z is up and u = 0.5 - atan2(y, x) / 2 pi,
    // v = 0.5 + atan2(z, hypot(x, y)) / pi. environment_to_world rotates that frame into the
    // scene (identity for Blender's Z-up scenes).
    std::int32_t environment_texture = -1;
    glm::mat3 environment_to_world{1.0f};
    // Blender's light groups (View Layer > Light Groups; docs/light_groups.md): their names, in
    // pass order. Each gets a Combined-like pass of the light from its lights, emissive
    // materials and (world_light_group) the world; empty: no group passes are compiled.
    std::vector<std::string> light_groups;
    std::int32_t world_light_group = -1;
    // Light linking and shadow linking (docs/light_linking.md): one row per receiver kind,
    // each a mask of the emitters' link sets (Light::light_link_set, Material::light_link_set;
    // the world's is 0): bit s of light_link_receives[r] says that light of link set s reaches
    // materials of row r (Material::light_link_row), bit s of shadow_link_blocks[r] that they
    // shadow it. Both empty (every set and row 0): no links, nothing of it is compiled.
    std::vector<std::uint32_t> light_link_receives;
    std::vector<std::uint32_t> shadow_link_blocks;
    // Motion blur (scene/motion.h): empty renders the frame at one instant.
    SceneMotion motion;
};

// A scene that owns its arrays (procedural scenes, loaders, tests).
struct OwnedMesh {
    std::vector<glm::vec3> positions;
    std::vector<glm::uvec3> triangles;
    std::vector<glm::vec3> normals;
    std::vector<glm::vec2> uvs;
    std::vector<std::uint32_t> material_ids;
    std::vector<glm::vec4> tangents;
    std::vector<glm::vec3> colors;

    // Appends another mesh's triangles, all with one material.
    void append(const std::vector<glm::vec3>& p, const std::vector<glm::uvec3>& t,
                std::uint32_t material);
    MeshView view() const {
        return {positions, triangles, normals, uvs, material_ids, tangents, colors};
    }
    // Multiplies every position by `factor` (normals and uvs unchanged).
    void scale(float factor);
};

// Makes a Scene whose MeshView points into `mesh`, which the Scene then owns.
Scene make_scene(std::shared_ptr<OwnedMesh> mesh);

}  // namespace glslppm
