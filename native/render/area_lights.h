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

// Per-material flags beside the Material the GPU reads (shaders/common/bsdf.glsl).
enum MaterialFlag : std::uint32_t {
    kMaterialLightSurface = 1u,      // rays add its emission and continue through it
    kMaterialHiddenFromCamera = 2u,  // camera rays pass it without adding emission
    kMaterialOneSidedEmission = 4u,  // emits from its front face only
    kMaterialCastsNoShadow = 8u,     // photons pass through (stored on diffuse ones)
    kMaterialMayBeTransparent = 16u, // a Mix with a Transparent leaf: shadow rays may pass
    kMaterialHiddenFromReflections = 32u,  // eye rays after a bounce pass it
    kMaterialVertexColor = 64u,      // its colour times the hit's vertex colour
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

}  // namespace glslppm
