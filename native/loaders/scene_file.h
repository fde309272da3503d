// Scene files for the command-line renderer and the Python module: glTF 2.0 (.gltf, .glb)
// and Wavefront OBJ/MTL (.obj), chosen by extension. Features the renderer lacks are
// approximated with a warning that names the element; unreadable input is a
// SceneFileError naming the file, the element and what is wrong.
#pragma once

#include <string>
#include <vector>

#include "scene/mesh.h"
#include "scene/scene.h"

namespace glslppm {

class SceneFileError : public SceneError {
  public:
    using SceneError::SceneError;
};

struct LoadedScene {
    Scene scene;
    std::vector<std::string> warnings;
    bool has_camera = false;  // false: the camera frames the bounds (and a warning says so)
};

// `aspect` is the render's width / height (glTF cameras give a vertical field of view).
LoadedScene load_scene_file(const std::string& path, float aspect);

// A camera looking down -Z (the files' forward axis) that frames the mesh's bounding sphere
// with the default 50 mm lens, for files without a camera (instances included).
Camera camera_framing_bounds(const Scene& scene, float aspect);

}  // namespace glslppm
