#include "scenes/instances_scene.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "scenes/shapes.h"

namespace glslppm {
namespace {

float hash01(std::uint32_t seed, std::uint32_t i) {
    std::uint32_t z = seed * 0x9E3779B9u + i * 0x85EBCA6Bu + 0x27D4EB2Fu;
    z = (z ^ (z >> 16)) * 0x7FEB352Du;
    z = (z ^ (z >> 15)) * 0x846CA68Bu;
    z ^= z >> 16;
    return static_cast<float>(z >> 8) * (1.0f / 16777216.0f);
}

// The room and the one instanced mesh, kept alive together by the Scene.
struct Meshes {
    OwnedMesh room, sphere;
};

}  // namespace

Scene make_instances_scene(std::size_t count, std::size_t triangles, std::uint32_t seed) {
    auto meshes = std::make_shared<Meshes>();
    using V = glm::vec3;
    for (const Shape& q : {make_quad(V(-1, 0, -1), V(-1, 0, 1), V(1, 0, 1), V(1, 0, -1)),
                           make_quad(V(-1, 2, -1), V(1, 2, -1), V(1, 2, 1), V(-1, 2, 1)),
                           make_quad(V(-1, 0, -1), V(1, 0, -1), V(1, 2, -1), V(-1, 2, -1)),
                           make_quad(V(-1, 0, -1), V(-1, 2, -1), V(-1, 2, 1), V(-1, 0, 1)),
                           make_quad(V(1, 0, -1), V(1, 0, 1), V(1, 2, 1), V(1, 2, -1))})
        meshes->room.append(q.positions, q.triangles, 0);
    const float l = 0.3f, y = 1.98f;
    const Shape light = make_quad(V(-l, y, -l), V(l, y, -l), V(l, y, l), V(-l, y, l));
    meshes->room.append(light.positions, light.triangles, 1);

    // make_sphere gives 4 r^2 - 4 r triangles for r rings (segments = 2 r).
    const double r =
        0.5 * (1.0 + std::sqrt(1.0 + static_cast<double>(std::max<std::size_t>(triangles, 24))));
    const int rings = std::max(3, static_cast<int>(std::lround(r)));
    Shape s = make_sphere(V(0.0f), 1.0f, rings, 2 * rings);
    for (V& p : s.positions) {
        const float theta = std::acos(std::clamp(p.y, -1.0f, 1.0f));
        const float phi = std::atan2(p.z, p.x);
        p *= 1.0f + 0.15f * std::sin(7.0f * theta) * std::sin(5.0f * phi);
    }
    meshes->sphere.append(s.positions, s.triangles, 0);

    Scene scene;
    scene.mesh = meshes->room.view();
    scene.instance_meshes = {meshes->sphere.view()};
    scene.keepalive = meshes;
    scene.materials = {
        {MaterialKind::Diffuse, glm::vec3(0.75f), 1.5f, glm::vec3(0.0f)},             // room
        {MaterialKind::Diffuse, glm::vec3(0.0f), 1.5f, glm::vec3(17.0f)},             // light
        {MaterialKind::Diffuse, glm::vec3(0.7f, 0.5f, 0.3f), 1.5f, glm::vec3(0.0f)},  // spheres
    };
    // k x k cells over the floor, k = ceil(sqrt(count)); radius about 0.35 of a cell.
    const auto k = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(count))));
    const float cell = 1.8f / static_cast<float>(std::max<std::size_t>(k, 1));
    for (std::size_t i = 0; i < count; ++i) {
        const auto id = static_cast<std::uint32_t>(i);
        const float radius = 0.35f * cell * (0.7f + 0.3f * hash01(seed, 4 * id));
        const float angle = 6.2831853f * hash01(seed, 4 * id + 1);
        const float stretch = 0.8f + 0.4f * hash01(seed, 4 * id + 2);
        const V centre(-0.9f + cell * (static_cast<float>(i % k) + 0.5f), 1.2f * radius,
                       -0.9f + cell * (static_cast<float>(i / k) + 0.5f));
        const float c = std::cos(angle), sn = std::sin(angle);
        Instance inst;
        inst.mesh = 0;
        inst.material_offset = 2;
        const float mirror = i % 2 ? -1.0f : 1.0f;
        inst.to_world =
            glm::mat4(glm::vec4(mirror * radius * c, 0, mirror * radius * -sn, 0),
                      glm::vec4(0, radius * stretch, 0, 0),
                      glm::vec4(radius * sn, 0, radius * c, 0), glm::vec4(centre, 1.0f));
        scene.instances.push_back(inst);
    }
    const V eye(0.0f, 1.7f, 3.2f), back = glm::normalize(eye - V(0.0f, 0.35f, -0.1f));
    const V right = glm::normalize(glm::cross(V(0, 1, 0), back));
    scene.camera.to_world =
        glm::mat4(glm::vec4(right, 0.0f), glm::vec4(glm::cross(back, right), 0.0f),
                  glm::vec4(back, 0.0f), glm::vec4(eye, 1.0f));
    scene.camera.fov_x = 0.75f;
    return scene;
}

}  // namespace glslppm
