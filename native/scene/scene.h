// The scene as the renderer takes it: world-space triangles (a MeshView whose arrays the
// caller keeps alive), the material table, lights, camera and environment. The add-on, the
// loaders and the procedural scenes all fill this one struct.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/mesh.h"

namespace glslppm {

// The closed material model (DESIGN.md): every Blender material maps onto one of these.
enum class MaterialKind : std::uint32_t { Diffuse = 0, Conductor = 1, Dielectric = 2 };

struct Material {
    MaterialKind kind = MaterialKind::Diffuse;
    glm::vec3 color{0.8f};     // albedo (diffuse), reflectance (conductor), tint (dielectric)
    float ior = 1.5f;          // dielectric only
    glm::vec3 emission{0.0f};  // emitted radiance, one-sided along the geometric normal
};

// Lights use Blender's units, so that the add-on hands them over unchanged:
// point and spot: power in watts (radiant intensity power / (4 pi) W/sr, spots not
// concentrated into their cone, as in Cycles); sun: strength = irradiance in W/m^2.
enum class LightKind : std::uint32_t { Point = 0, Spot = 1, Sun = 2 };

struct Light {
    LightKind kind = LightKind::Point;
    glm::vec3 color{1.0f};
    float power = 1.0f;
    glm::vec3 position{0.0f};
    glm::vec3 direction{0.0f, 0.0f, -1.0f};  // the direction light travels (spot, sun)
    float spot_size = 0.785398f;             // full cone angle, radians (Blender's spot_size)
    float spot_blend = 0.15f;                // Blender's spot_blend
    float radius = 0.0f;                     // point/spot soft size (later)
    float angle = 0.0f;                      // sun angular diameter (later)
};

enum class Projection : std::uint32_t { Perspective = 0, Orthographic = 1 };

// Looks down its local -Z with +Y up, as a Blender camera does.
struct Camera {
    glm::mat4 to_world{1.0f};
    float fov_x = 0.691111f;  // full horizontal angle of view, radians (Blender's 50 mm lens)
    float shift_x = 0.0f;     // Blender's shift: fraction of the larger image dimension
    float shift_y = 0.0f;
    Projection projection = Projection::Perspective;
    float ortho_scale = 6.0f;
    float aperture_radius = 0.0f;
    float focus_distance = 10.0f;
};

struct Scene {
    MeshView mesh;
    std::shared_ptr<const void> keepalive;  // owns the arrays the MeshView points into
    std::vector<Material> materials;
    std::vector<Light> lights;
    Camera camera;
    glm::vec3 environment{0.0f};  // constant radiance of the world
};

// A scene that owns its arrays (procedural scenes, loaders, tests).
struct OwnedMesh {
    std::vector<glm::vec3> positions;
    std::vector<glm::uvec3> triangles;
    std::vector<glm::vec3> normals;
    std::vector<glm::vec2> uvs;
    std::vector<std::uint32_t> material_ids;

    // Appends another mesh's triangles, all with one material.
    void append(const std::vector<glm::vec3>& p, const std::vector<glm::uvec3>& t,
                std::uint32_t material);
    MeshView view() const { return {positions, triangles, normals, uvs, material_ids}; }
};

// Makes a Scene whose MeshView points into `mesh`, which the Scene then owns.
Scene make_scene(std::shared_ptr<OwnedMesh> mesh);

}  // namespace glslppm
