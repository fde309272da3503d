// The emitters photons start from and light samples pick, as the GPU reads them
// (shaders/common/emitters.glsl): emissive triangles (meshes' emission and area lights'),
// point, spot and sun lights and the environment, each with its emitted power, picked in
// proportion to it (docs/architecture.md, "Words": a light is the scene's object, an emitter
// a record of this table). A GpuEmitter (render/gpu_layout.h) per emitter:
//   [0] (a.xyz, intBitsToFloat(kind))
//   [1] (b.xyz, b.w)       triangle: v1, two-sided 0/1; point: (0, radius); spot: axis,
//                          cos(half angle);
//                          sun: direction, cos(half the angular diameter)
//   [2] (c.xyz, cdf)       triangle: v2; spot: (smooth width, radius, cosine falloff 0/1);
//                          cdf: cumulative pick
//                          probability up to and including this emitter
//   [3] (power.rgb, pick probability)
// with a = v0 (triangle) or position (point, spot). A photon carries power / probability, so
// the mean flux of emitted photons is the total power (the energy test checks this).
//
// Where BSDF samples at visible points meet emitters (multiple importance sampling,
// HAS_EMITTER_MIS: shaders/common/light_sampling.glsl), the records are followed by the
// triangles' map (append_triangle_map): one int per packed triangle, its record's index or
// -1, four to a vec4, so that a ray that hits a triangle finds the pick probability light
// sampling would have chosen that point with.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "bvh/packed_bvh.h"
#include "render/environment_map.h"
#include "scene/scene.h"

namespace glslppm {

enum class EmitterKind : int {
    Triangle = EMITTER_TRIANGLE,
    Point = EMITTER_POINT,
    Spot = EMITTER_SPOT,
    Sun = EMITTER_SUN,
    Environment = EMITTER_ENVIRONMENT,
};

struct EmitterTable {
    std::vector<glm::vec4> records;  // EMITTER_VEC4 per emitter (common/records.glsl)
    glm::vec3 total_power{0.0f};     // watts, per channel
    std::size_t count = 0;
    bool has[5] = {false, false, false, false, false};  // by EmitterKind
    // Per packed triangle of the BVH, the index of its record, or -1 (not emitting).
    std::vector<std::int32_t> triangle_records;
    // The point, spot and sun lights' records: [first_light, first_light + light_count).
    std::size_t first_light = 0, light_count = 0;
    // Per scene light, the index of its record, or -1 (an area light, or dark).
    std::vector<std::int32_t> light_records;
};

// Bounding sphere of the scene (distant emitters, the sun and the world, shine through its
// disc).
struct SceneBounds {
    glm::vec3 lo{0.0f}, hi{0.0f};
    glm::vec3 center() const { return 0.5f * (lo + hi); }
    float radius() const { return 0.5f * glm::length(hi - lo); }
};

SceneBounds scene_bounds(const PackedBvh& bvh);

// Throws SceneError when nothing emits light. `materials` is the scene's table with the area
// lights' appended (render/area_lights.h); `environment` is the map's distribution, if any.
EmitterTable build_emitters(const Scene& scene, const std::vector<Material>& materials,
                            const PackedBvh& bvh, const SceneBounds& bounds,
                            const EnvironmentMap* environment);

// A point, spot or sun light's record (EMITTER_VEC4 vec4s from `record`) moved to where
// `light` stands and shines (motion blur: render/light_motion.cpp); its power, radius and
// cone stay.
void place_light(const Light& light, glm::vec4* record);

// How a light sample's pick is split between the world and the other emitters at a shading
// point (common/light_sampling.glsl, light_world_share): the other emitters' power-weighted
// centre (xyz) and spread (w, the mean squared distance from it), and (x) their luminance
// power but the suns', (y) the suns' luminance irradiance, (z) the world's (pi times its mean
// radiance), (w) the world's share of the power-based pick (0: no world, 1: the world alone).
struct LightSplit {
    glm::vec4 centre{0.0f};
    glm::vec4 power{0.0f};
};

LightSplit light_split(const EmitterTable& table, float scene_radius);

// Appends triangle_records to the records (as int bits, four per vec4, -1 padding), the
// GPU's map from a hit triangle to its emitter (emitters.glsl, triangle_emitter).
void append_triangle_map(EmitterTable& table);

}  // namespace glslppm
