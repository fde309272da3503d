// The scene's preparation for the GPU, done on the CPU without GL, as named steps (Cycles'
// scene managers, called in order): validate, flatten or instance, tangents, BVH,
// environment, emitters, features, camera and radius (the Frame). The Renderer uploads what
// this returns; GoogleTest checks each step without EGL (tests/native/scene_preparation_test.cpp,
// tests/native/preparation_steps_test.cpp).
#pragma once

#include <cstdint>
#include <list>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "bvh/packed_bvh.h"
#include "bvh/two_level_bvh.h"
#include "render/area_lights.h"
#include "render/emitters.h"
#include "render/environment_map.h"
#include "render/gpu_layout.h"
#include "render/instancing.h"
#include "render/motion.h"
#include "render/settings.h"
#include "scene/cancel.h"
#include "scene/scene.h"

namespace glslppm {

// Which images the render needs: base-colour textures of materials on triangles that have
// uvs, and the environment map.
struct TextureUse {
    bool materials = false, environment = false;
    std::vector<bool> used;  // per scene texture
};

// What the pipeline keeps of a prepared scene, taken whole (Renderer::Gpu::scene): the
// programs' defines, the sizes, the Frame, the emitter table and what decides whether a
// later scene can reuse the programs (update_tables).
struct PipelineScene {
    InstancePlan instancing;
    std::size_t instance_count = 0;  // the scene's instances, traced or flattened
    TextureUse textures;
    // The prepared geometry's triangles (area lights included) and materials.
    std::size_t geometry_triangles = 0, material_count = 0;
    SceneBounds bounds;
    EmitterTable emitters;
    // The programs' #defines and the variant's name (stats()["variant"]).
    std::vector<std::pair<std::string, std::string>> defines;
    std::string variant;
    // HAS_VERTEX_COLORS: a material multiplies in the meshes' vertex colours (uploaded with
    // the BVH); a visible point holds its colour in its fifth vec4.
    bool vertex_colors = false;
    // HAS_LIGHT_TRACING: photons of L S+ paths splat to the camera (common/light_tracing.glsl)
    // into the light splat buffer, folded in at the end of every pass.
    bool light_tracing = false;
    PassLayout pass_layout;  // the render passes' records in the pass films
    std::uint32_t pixels = 0, photon_threads = 0, hash_cells = 0;
    FrameBlock frame{};
    float initial_radius = 0.0f;
    std::vector<std::string> warnings;
    // Motion blur (render/motion.h): what moves in the shutter; null when nothing does (then
    // nothing of it runs: the passes are those of a scene without motion).
    std::shared_ptr<const MotionPlan> motion;
};

struct PreparedScene : PipelineScene {
    SceneGeometry geometry;  // the scene's mesh and materials, area lights appended
    // Two levels: the instance meshes as traced (uvs and colours only where used), and the
    // instances as traced: the scene's, except that those placed once (emitting, where
    // instances move: InstancePlan::placed_once) take an empty mesh, the last one here.
    std::vector<MeshView> instance_meshes;
    std::vector<Instance> traced_instances;
    PackedBvh bvh;  // the triangles placed once (with the area lights)
    // The two-level MTBVH (the placed-once triangles its mesh 0) when instances are traced
    // that way (instancing.two_level); null otherwise (flattened into `bvh`).
    std::unique_ptr<TwoLevelBvh> two_level;
    std::unique_ptr<EnvironmentMap> environment;  // null without an environment map
    // The Materials buffer: GpuMaterial records, then albedo tables.
    std::vector<glm::vec4> material_records;
    // Tangents made from the uvs for normal-mapped meshes that came without (the MeshViews
    // of `geometry` and `instance_meshes` point into these; a list never moves them).
    std::list<std::vector<glm::vec4>> generated_tangents;
};

// The material table's records (material_records.cpp).

// GpuMaterial::normal_map for a material (render/gpu_layout.h).
std::uint32_t normal_map_word(const Material& m);

// Whether a material needs the lobes beyond Lambert, mirror and smooth glass (HAS_ROUGH_LOBES).
bool needs_rough_lobes(const Material& m);

// The Materials buffer: GpuMaterial records (flags: one per material), then the albedo
// tables the rough lobes need (one shared by every conductor, one per dielectric or plastic
// index), as vec4s. `textures`: the texture indices are kept; `vertex_colors`: materials that
// ask for vertex colours get kMaterialVertexColor.
std::vector<glm::vec4> material_records(const std::vector<Material>& materials,
                                        const std::vector<std::uint32_t>& flags, bool textures,
                                        bool vertex_colors = false);

// Throws SceneError / std::invalid_argument naming what is wrong, Cancelled when `cancel` is
// set. local_size is the stages' work-group size (a #define of every program). `built`, when
// given, is this scene's MTBVH from an earlier preparation, used instead of building one (the
// scene's materials, lights, world or camera changed, not its geometry); p.bvh stays empty.
// flatten_max_triangles: the devices' bound for flattening instances (render/instancing.h).
PreparedScene prepare_scene(const Scene& scene, const RenderSettings& settings,
                            unsigned local_size, const CancelFlag* cancel = nullptr,
                            const PackedBvh* built = nullptr,
                            std::size_t flatten_max_triangles = kFlattenMaxTrianglesSoftware);

// The steps of prepare_scene, in its order, each tested on its own
// (tests/native/preparation_steps_test.cpp). Each fills its part of `p`.

// validate: the settings and the scene as given (std::invalid_argument, SceneError).
void validate_inputs(const Scene& scene, const RenderSettings& settings);

// flatten or instance (prepare_geometry.cpp): area lights join the geometry; instances are
// flattened into it or kept for two levels (p.instancing, p.instance_meshes; p.bounds of
// an instanced scene); textures count only where the meshes have uvs (p.textures) and
// vertex colours only where a material multiplies them in (p.vertex_colors).
void flatten_or_instance(const Scene& scene, const RenderSettings& settings,
                         std::size_t flatten_max_triangles, PreparedScene& p);

// Whether the materials read normal or bump maps (HAS_NORMAL_MAP): then every mesh with
// uvs needs tangents.
bool uses_normal_maps(const PreparedScene& p);

// tangents: meshes without them get tangents from their uvs (scene/tangent_space.h) where
// uses_normal_maps(p).
void generate_missing_tangents(PreparedScene& p);

// BVH: the MTBVH of the placed-once triangles (or `built`, an earlier one of the same
// geometry: p.bvh stays empty), the two-level MTBVH on that path, and the scene's bounds.
// Returns the MTBVH of the placed-once triangles. SceneError for a scene without
// triangles or of a size floats do not render.
const PackedBvh& build_bvh(const Scene& scene, const RenderSettings& settings,
                           const CancelFlag* cancel, const PackedBvh* built, PreparedScene& p);

// environment: the environment map's sampling distribution (p.environment), where the
// scene has one.
void prepare_environment(const Scene& scene, PreparedScene& p);

// emitters: the emitter table (render/emitters.h) of the placed-once triangles in `bvh`.
void prepare_emitters(const Scene& scene, const PackedBvh& bvh, PreparedScene& p);

// features (scene_features.cpp): the programs' #defines and the variant's name: only what
// the scene uses is compiled (DESIGN.md, "model only what a scene requires").
void choose_features(const Scene& scene, const RenderSettings& settings, unsigned local_size,
                     const PackedBvh& bvh, PreparedScene& p);

// Light tracing (HAS_LIGHT_TRACING, scene_features.cpp): allowed where the setting is on and
// neither depth of field, a camera frame with scale or shear, the light split's passes nor
// the full variant rules it out; choose_features turns it on where a traced material is
// also a conductor or dielectric and none is a cut-out. light_tracing_expected answers
// that from the scene's materials before anything is prepared (the memory estimate), the
// same wherever every mirror or glass material is used by a triangle.
bool light_tracing_allowed(const Scene& scene, const RenderSettings& settings);
bool light_tracing_expected(const Scene& scene, const RenderSettings& settings);

// frame (camera_frame.cpp): the sizes and the Frame's constants, the camera's part and the
// automatic radius (p.initial_radius) through `bvh` included.
void fill_frame(const Scene& scene, const RenderSettings& settings, const PackedBvh& bvh,
                PreparedScene& p);

// The camera's part of the Frame (film extent and shift, projection, depth of field) at the
// settings' image size, and the automatic radius it implies (settings.initial_radius when
// positive): two pixel footprints at the median distance the camera sees, through `bvh`.
float frame_camera(const Camera& camera, const RenderSettings& settings, const PackedBvh& bvh,
                   const SceneBounds& bounds, FrameBlock& frame,
                   const TwoLevelBvh* two_level = nullptr);

// camera: frame_camera's first half: the Frame's camera fields. Returns the whole frame's
// film, which the automatic radius looks through (a region's window is part of it).
struct WholeFilm {
    glm::vec2 half_extent{0.0f}, shift{0.0f};
    int width = 0, height = 0;  // pixels
};
WholeFilm camera_frame(const Camera& camera, const RenderSettings& settings, FrameBlock& frame);

// radius: two pixel footprints at the median distance the camera sees through `film`, at
// most 5% of the scene's diagonal; settings.initial_radius when positive.
float automatic_radius(const Camera& camera, const RenderSettings& settings,
                       const FrameBlock& frame, const WholeFilm& film, const PackedBvh& bvh,
                       const SceneBounds& bounds, const TwoLevelBvh* two_level = nullptr);

}  // namespace glslppm
