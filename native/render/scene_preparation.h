// The scene's preparation for the GPU, done on the CPU without GL: validation, the geometry
// with its area lights, the MTBVH, the emitter table and the environment's distribution, the
// feature set the programs are specialized for, the camera's Frame and the automatic
// radius. The Renderer uploads what this returns; GoogleTest checks it without EGL
// (tests/native/scene_preparation_test.cpp).
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

struct PreparedScene {
    SceneGeometry geometry;  // the scene's mesh and materials, area lights appended
    TextureUse textures;
    PackedBvh bvh;  // the triangles placed once (with the area lights)
    // The scene's instances: how they are traced, and the two-level MTBVH (the placed-once
    // triangles its mesh 0) when that is the path; null otherwise (flattened into `bvh`).
    InstancePlan instancing;
    std::unique_ptr<TwoLevelBvh> two_level;
    SceneBounds bounds;
    std::unique_ptr<EnvironmentMap> environment;  // null without an environment map
    EmitterTable emitters;
    // The programs' #defines and the variant's name (stats()["variant"]).
    std::vector<std::pair<std::string, std::string>> defines;
    std::string variant;
    // HAS_VERTEX_COLORS: a material multiplies in the meshes' vertex colours (uploaded with
    // the BVH); a visible point holds its colour in its fifth vec4.
    bool vertex_colors = false;
    PassLayout pass_layout;  // the render passes' records in the pass films
    // The Materials buffer: GpuMaterial records, then albedo tables.
    std::vector<glm::vec4> material_records;
    std::uint32_t pixels = 0, photon_threads = 0, hash_cells = 0;
    FrameBlock frame{};
    float initial_radius = 0.0f;
    std::vector<std::string> warnings;
    // Tangents made from the uvs for normal-mapped meshes that came without (the MeshViews
    // of `geometry` and the instance meshes point into these; a list never moves them).
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

// The camera's part of the Frame (film extent and shift, projection, depth of field) at the
// settings' image size, and the automatic radius it implies (settings.initial_radius when
// positive): two pixel footprints at the median distance the camera sees, through `bvh`.
float frame_camera(const Camera& camera, const RenderSettings& settings, const PackedBvh& bvh,
                   const SceneBounds& bounds, FrameBlock& frame,
                   const TwoLevelBvh* two_level = nullptr);

}  // namespace glslppm
