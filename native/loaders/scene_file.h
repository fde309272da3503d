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

// How an OBJ file's MTL materials are read. `Standard`: the MTL specification's illum
// models, Ke emission and Ns roughness as Blender writes and reads them. `Glslppm2015`: the
// convention of the scene files of Hachisuka's original glslppm (2015): Ka marks a light,
// Ks 1 with Ns 100 a mirror, a name starting with "glass" a glass (docs/materials.md has
// the whole table).
enum class MtlConvention { Standard, Glslppm2015 };

// "standard" or "glslppm2015"; anything else is std::invalid_argument naming the choices.
MtlConvention parse_mtl_convention(const std::string& name);
const char* to_string(MtlConvention convention);

struct SceneFileOptions {
    MtlConvention mtl = MtlConvention::Standard;  // .obj only: refused for glTF files
};

// `aspect` is the render's width / height (glTF cameras give a vertical field of view).
LoadedScene load_scene_file(const std::string& path, float aspect,
                            const SceneFileOptions& options = {});

// A camera looking down -Z (the files' forward axis) that frames the mesh's bounding sphere
// with the default 50 mm lens, for files without a camera (instances included).
Camera camera_framing_bounds(const Scene& scene, float aspect);

}  // namespace glslppm
