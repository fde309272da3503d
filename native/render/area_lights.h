// Area lights as geometry: each becomes emissive triangles (a quad, or a 64-sided fan for
// disks and ellipses) that camera rays and specular chains can see, with a material that
// emits L = P / (pi A) from its front (the light's local -Z, as in Blender) and lets every
// ray pass on through, as Cycles' lights do (they cast no shadow).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "scene/scene.h"

namespace glslppm {

// Per-material flags beside the Material the GPU reads (GpuMaterial::flags).
enum MaterialFlag : std::uint32_t {
    // The bits' values are shaders/common/records.glsl's (MATERIAL_LIGHT_SURFACE, ...).
    kMaterialLightSurface = MATERIAL_LIGHT_SURFACE,    // rays add its emission and pass on
    kMaterialHiddenFromCamera = MATERIAL_HIDDEN_FROM_CAMERA,  // camera rays pass it unlit
    kMaterialOneSidedEmission = MATERIAL_ONE_SIDED_EMISSION,  // emits from its front only
    kMaterialCastsNoShadow = MATERIAL_CASTS_NO_SHADOW,  // photons pass (stored on diffuse)
    kMaterialMayBeTransparent = MATERIAL_MAY_BE_TRANSPARENT,  // a Mix with a Transparent leaf
    kMaterialHiddenFromReflections = MATERIAL_HIDDEN_FROM_REFLECTIONS,  // later eye rays pass
    kMaterialVertexColor = MATERIAL_VERTEX_COLOR,  // its colour times the vertex colour
};

// The mesh and material table the renderer builds its BVH from: the scene's own when it has
// no area lights (no copy), else a copy with the lights' triangles appended.
struct SceneGeometry {
    std::shared_ptr<OwnedMesh> owned;
    MeshView mesh;
    std::vector<Material> materials;
    std::vector<std::uint32_t> flags;  // one per material
};

SceneGeometry with_area_lights(const Scene& scene);

// An area light's outline in world space (light.to_world): its triangles are the fan
// (0, k, k + 1), appended after the scene's own triangles, light by light.
std::vector<glm::vec3> area_light_corners(const Light& light);

}  // namespace glslppm
