#include "loaders/gltf_punctual.h"

#include <algorithm>
#include <cmath>

#include "loaders/scene_file.h"

namespace glslppm::gltf {
namespace {

// Blender's glTF importer (io_scene_gltf2, light.py, lighting mode "Standard"): photometric
// glTF units become radiometric Blender units at 683 lm/W.
constexpr double kWattsToLumens = 683.0;
constexpr double kPi = 3.14159265358979323846;

[[noreturn]] void fail(const std::string& file, const std::string& element,
                       const std::string& what) {
    throw SceneFileError(file + ": " + element + ": " + what);
}

// A number in the light's extras, or `fallback` where the key is absent; anything but a
// finite number >= 0 is an error naming the key.
float extras_number(const tinygltf::Light& l, const char* key, float fallback,
                    const std::string& file, const std::string& element) {
    if (!l.extras.IsObject() || !l.extras.Has(key)) return fallback;
    const tinygltf::Value& v = l.extras.Get(key);
    const double x = v.IsNumber() ? v.GetNumberAsDouble() : -1.0;
    if (!(x >= 0.0) || !std::isfinite(x))
        fail(file, element, std::string("extras.") + key + " must be a finite number >= 0");
    return float(x);
}

}  // namespace

Camera convert_camera(const tinygltf::Camera& c, const glm::mat4& to_world, float aspect,
                      const std::string& file, const std::string& element) {
    Camera camera;
    for (int axis = 0; axis < 3; ++axis) {
        const glm::vec3 column(to_world[axis]);
        const float length = glm::length(column);
        if (!(length > 0.0f) || !std::isfinite(length))
            fail(file, element, "the camera's node transform is singular");
        camera.to_world[axis] = glm::vec4(column / length, 0.0f);
    }
    camera.to_world[3] = to_world[3];
    if (c.type == "perspective") {
        const double yfov = c.perspective.yfov;
        if (!(yfov > 0.0 && yfov < kPi)) fail(file, element, "yfov must be in (0, pi)");
        // tan(fov_x / 2) = aspect * tan(yfov / 2), with the render's aspect ratio.
        camera.fov_x = float(2.0 * std::atan(std::tan(0.5 * yfov) * double(aspect)));
    } else if (c.type == "orthographic") {
        const double xmag = std::abs(c.orthographic.xmag), ymag = std::abs(c.orthographic.ymag);
        if (!(xmag > 0.0 || ymag > 0.0) || !std::isfinite(xmag) || !std::isfinite(ymag))
            fail(file, element, "orthographic xmag and ymag must be finite and not both zero");
        camera.projection = Projection::Orthographic;
        // Blender's ortho_scale spans the larger image side; xmag, ymag are half extents.
        camera.ortho_scale = float(2.0 * std::max(xmag, ymag * double(aspect)));
    } else {
        fail(file, element, "type '" + c.type + "' is neither perspective nor orthographic");
    }
    return camera;
}

std::optional<Light> convert_light(const tinygltf::Light& l, const glm::mat4& to_world,
                                   const std::string& file, const std::string& element,
                                   std::vector<std::string>& warnings) {
    Light light;
    if (l.color.size() >= 3) light.color = glm::vec3(l.color[0], l.color[1], l.color[2]);
    if (!(l.intensity >= 0.0) || !std::isfinite(l.intensity))
        fail(file, element, "intensity must be finite and >= 0");
    if (!(light.color.x >= 0.0f && light.color.y >= 0.0f && light.color.z >= 0.0f) ||
        !std::isfinite(light.color.x + light.color.y + light.color.z))
        fail(file, element, "color must be finite and >= 0");
    light.position = glm::vec3(to_world[3]);
    const glm::vec3 forward = glm::mat3(to_world) * glm::vec3(0.0f, 0.0f, -1.0f);
    const float length = glm::length(forward);
    if (!(length > 0.0f) || !std::isfinite(length))
        fail(file, element, "the light's node transform is singular");
    light.direction = forward / length;
    if (l.range > 0.0)
        warnings.push_back(file + ": " + element +
                           ": range is not supported: the light reaches everywhere");
    if (l.type == "point" || l.type == "spot") {
        light.kind = LightKind::Point;
        light.power = float(l.intensity * 4.0 * kPi / kWattsToLumens);
        if (l.type == "spot") {
            const double outer = l.spot.outerConeAngle, inner = l.spot.innerConeAngle;
            if (!(outer > 0.0 && outer <= 0.5 * kPi) || !(inner >= 0.0 && inner <= outer))
                fail(file, element,
                     "spot cone angles need 0 <= innerConeAngle <= outerConeAngle <= pi/2");
            light.kind = LightKind::Spot;
            light.spot_size = float(2.0 * outer);
            light.spot_blend = float(1.0 - inner / outer);
        }
    } else if (l.type == "directional") {
        light.kind = LightKind::Sun;
        light.power = float(l.intensity / kWattsToLumens);
    } else {
        warnings.push_back(file + ": " + element + ": type '" + l.type +
                           "' is not point, spot or directional: skipped");
        return std::nullopt;
    }
    if (!std::isfinite(light.power)) fail(file, element, "intensity is too large");
    // glTF lights are points; extras carry Blender's size where the writer kept it.
    if (light.kind == LightKind::Sun) {
        light.angle = extras_number(l, "angle", 0.0f, file, element);
        if (light.angle >= float(kPi)) fail(file, element, "extras.angle must be below pi");
    } else {
        light.radius = extras_number(l, "radius", 0.0f, file, element);
        if (l.extras.IsObject() && l.extras.Has("soft_falloff")) {
            const tinygltf::Value& v = l.extras.Get("soft_falloff");
            if (!v.IsBool()) fail(file, element, "extras.soft_falloff must be true or false");
            light.facing_disc = v.Get<bool>();
        } else {
            light.facing_disc = light.radius > 0.0f;  // Blender's default: Soft Falloff on
        }
    }
    return light;
}

}  // namespace glslppm::gltf
