// The one validation of a Scene's materials, lights, camera, world and textures, with one
// policy for every field: a bad value is rejected with a SceneError that names it
// ("lights[2].power: -1 is negative"), never dropped or clamped. The renderer calls it for
// every entry point (module, loaders, CLI, fuzz targets); the mesh's arrays are checked by
// validate_mesh (scene/mesh.h) as they are read.
#pragma once

#include "scene/scene.h"

namespace glslppm {

void validate_scene(const Scene& scene);
// The camera alone, for a renderer whose camera changes (Renderer::set_camera).
void validate_camera(const Camera& camera);

}  // namespace glslppm
