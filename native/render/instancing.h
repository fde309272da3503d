// A scene's instances on their way to the GPU: whether they are traced through a two-level
// MTBVH (bvh/two_level_bvh.h) or flattened into world-space triangles, by a measured rule,
// and the flattening itself. The placed-once triangles (Scene::mesh with the area lights)
// are mesh 0 of the two-level tree, under an identity instance.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "render/settings.h"
#include "scene/scene.h"

namespace glslppm {

// Flatten when the flattened copy holds at most this many triangles; the bound depends on
// the device (docs/instancing.md, glslppm-bench passes --scene instances:NxM --instancing
// flattened|two-level).
// llvmpipe: the flattened MTBVH was 14% faster at 64 x 1k triangles, the two paths within
// noise at 4 x 4k and 16 x 4k, and the two-level one 24% faster at 256 x 4k (1M) and the
// only one that fits at 64 x 64k; the bound sits between 64k and 1M.
constexpr std::size_t kFlattenMaxTrianglesSoftware = 1u << 18;
// NVIDIA H200, 1024^2, 1M photons: flattened 52%, 50% and 42% faster at 1M, 2M and 4M
// instanced triangles (10, 20, 40 x 100k), two-level 4.3x faster at 8M (80 x 100k).
constexpr std::size_t kFlattenMaxTrianglesGpu = 1u << 22;

struct InstancePlan {
    bool two_level = false;
    std::string path;    // "none" (no instances), "two-level" or "flattened": stats()["instancing"]
    std::string reason;  // why, for stats and logs
    std::size_t instanced_triangles = 0;  // what the flattened copy holds (instances only)
    // Per instance, whether it emits light (one of its materials has an emission). Where
    // instances move and some emit, the emitting ones are placed once (flattened) and the
    // rest traced through the two levels; `placed_once` says so.
    std::vector<bool> emitting;
    bool placed_once = false;
};

// Checks the instances (mesh index, finite affine invertible transform, material offsets in
// range: SceneError naming the instance) and chooses the path.
// flatten_max_triangles: the device's bound above (Auto mode only). instances_move: some
// instances move in the shutter (render/motion.h), which only the two levels trace (their
// top level refitted per pass), whatever the mode; those that emit light are placed once
// with the other emitters (their motion rewritten per pass: MovingMeshEmitter).
InstancePlan plan_instancing(const Scene& scene, const std::vector<Material>& materials,
                             Instancing mode,
                             std::size_t flatten_max_triangles = kFlattenMaxTrianglesSoftware,
                             bool instances_move = false);

// `world` followed by every instance's triangles in world space: positions A x + T, normals
// A^-T n (not normalized: interpolated across a triangle and then normalized, they point as
// the two-level traversal's do), zero normals and uvs for meshes without them (the renderer
// then falls back to the geometric normal), material ids plus the instance's offset; the
// corners of a mirrored instance's triangles swapped so that their front sides stay.
// `only` (one per instance, or null for all): the instances to flatten; `first_triangle`
// (or null): each flattened instance's first triangle in the result (-1 for the others).
std::shared_ptr<OwnedMesh> flatten_instances(const MeshView& world, const Scene& scene,
                                             bool keep_uvs,
                                             const std::vector<bool>* only = nullptr,
                                             std::vector<std::int64_t>* first_triangle = nullptr);

// The box of a scene with instances, the same whichever path traces them (the photon hash
// grid, ray offsets and radius floors derive from it, so the two paths render alike): the
// placed-once triangles' vertices and, per instance, its mesh's vertex box mapped corner by
// corner (in double, rounded outwards).
void instanced_scene_bounds(const MeshView& world, const Scene& scene, glm::vec3& lo,
                            glm::vec3& hi);

}  // namespace glslppm
