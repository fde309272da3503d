#include "loaders/scene_file.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "loaders/gltf_loader.h"
#include "loaders/obj_loader.h"

namespace glslppm {
namespace {

std::string lower_extension(const std::string& path) {
    const auto dot = path.find_last_of('.');
    const auto slash = path.find_last_of('/');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
    std::string ext = path.substr(dot + 1);
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext;
}

}  // namespace

Camera camera_framing_bounds(const Scene& scene, float aspect) {
    Camera camera;
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (const glm::vec3& p : scene.mesh.positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    // Instances: every vertex of each placed mesh (files with instancing are small enough).
    for (const Instance& inst : scene.instances)
        for (const glm::vec3& p : scene.instance_meshes[inst.mesh].positions) {
            const glm::vec3 w(inst.to_world * glm::vec4(p, 1.0f));
            lo = glm::min(lo, w);
            hi = glm::max(hi, w);
        }
    if (!(lo.x <= hi.x)) lo = hi = glm::vec3(0.0f);
    const glm::vec3 center = 0.5f * (lo + hi);
    const float radius = std::max(0.5f * glm::length(hi - lo), 1e-6f);
    // The bounding sphere fits the narrower of the two angles of view, with a 5% margin.
    const float half_x = 0.5f * camera.fov_x;
    const float half_y = std::atan(std::tan(half_x) / aspect);
    const float distance = 1.05f * radius / std::sin(std::min(half_x, half_y));
    camera.to_world[3] = glm::vec4(center + glm::vec3(0.0f, 0.0f, distance), 1.0f);
    camera.focus_distance = distance;
    return camera;
}

MtlConvention parse_mtl_convention(const std::string& name) {
    if (name == "standard") return MtlConvention::Standard;
    if (name == "glslppm2015") return MtlConvention::Glslppm2015;
    throw std::invalid_argument("unknown MTL convention '" + name +
                                "' (expected standard or glslppm2015)");
}

const char* to_string(MtlConvention convention) {
    return convention == MtlConvention::Glslppm2015 ? "glslppm2015" : "standard";
}

LoadedScene load_scene_file(const std::string& path, float aspect,
                            const SceneFileOptions& options) {
    const std::string ext = lower_extension(path);
    LoadedScene loaded;
    if ((ext == "gltf" || ext == "glb") && options.mtl != MtlConvention::Standard)
        throw SceneFileError(path + ": the MTL convention '" + to_string(options.mtl) +
                             "' applies to .obj files only; this is a glTF file");
    if (ext == "gltf" || ext == "glb")
        loaded = load_gltf_file(path, aspect);
    else if (ext == "obj")
        loaded = load_obj_file(path, aspect, options.mtl);
    else
        throw SceneFileError(path + ": unknown scene file type '." + ext +
                             "' (expected .gltf, .glb or .obj)");
    if (!loaded.has_camera) {
        loaded.scene.camera = camera_framing_bounds(loaded.scene, aspect);
        loaded.warnings.push_back(path + ": no camera: one is placed to frame the whole scene");
    }
    return loaded;
}

}  // namespace glslppm
