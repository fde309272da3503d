#include "procedural/sphere_field_room.h"

#include <algorithm>
#include <cmath>

#include "procedural/shapes.h"

namespace glslppm {

std::vector<Material> sphere_field_materials() {
    return {
        {MaterialKind::Diffuse, glm::vec3(0.75f), 1.5f, glm::vec3(0.0f)},             // room
        {MaterialKind::Diffuse, glm::vec3(0.0f), 1.5f, glm::vec3(17.0f)},             // light
        {MaterialKind::Diffuse, glm::vec3(0.7f, 0.5f, 0.3f), 1.5f, glm::vec3(0.0f)},  // spheres
    };
}

void append_sphere_field_room(OwnedMesh& mesh) {
    using V = glm::vec3;
    for (const Shape& q : {make_quad(V(-1, 0, -1), V(-1, 0, 1), V(1, 0, 1), V(1, 0, -1)),
                           make_quad(V(-1, 2, -1), V(1, 2, -1), V(1, 2, 1), V(-1, 2, 1)),
                           make_quad(V(-1, 0, -1), V(1, 0, -1), V(1, 2, -1), V(-1, 2, -1)),
                           make_quad(V(-1, 0, -1), V(-1, 2, -1), V(-1, 2, 1), V(-1, 0, 1)),
                           make_quad(V(1, 0, -1), V(1, 0, 1), V(1, 2, 1), V(1, 2, -1))})
        mesh.append(q.positions, q.triangles, 0);
    const float l = 0.3f, y = 1.98f;
    const Shape light = make_quad(V(-l, y, -l), V(l, y, -l), V(l, y, l), V(-l, y, l));
    mesh.append(light.positions, light.triangles, 1);
}

Camera sphere_field_camera() {
    using V = glm::vec3;
    const V eye(0.0f, 1.7f, 3.2f), back = glm::normalize(eye - V(0.0f, 0.35f, -0.1f));
    const V right = glm::normalize(glm::cross(V(0, 1, 0), back));
    Camera camera;
    camera.to_world = glm::mat4(glm::vec4(right, 0.0f), glm::vec4(glm::cross(back, right), 0.0f),
                                glm::vec4(back, 0.0f), glm::vec4(eye, 1.0f));
    camera.fov_x = 0.75f;
    return camera;
}

float hash01(std::uint32_t seed, std::uint32_t i) {
    std::uint32_t z = seed * 0x9E3779B9u + i * 0x85EBCA6Bu + 0x27D4EB2Fu;
    z = (z ^ (z >> 16)) * 0x7FEB352Du;
    z = (z ^ (z >> 15)) * 0x846CA68Bu;
    z ^= z >> 16;
    return static_cast<float>(z >> 8) * (1.0f / 16777216.0f);
}

int sphere_rings_for(std::size_t budget) {
    const double r = 0.5 * (1.0 + std::sqrt(1.0 + static_cast<double>(budget)));
    return std::max(3, static_cast<int>(std::lround(r)));
}

float sphere_bump(const glm::vec3& p, float phase_a, float phase_b) {
    const float theta = std::acos(std::clamp(p.y, -1.0f, 1.0f));
    const float phi = std::atan2(p.z, p.x);
    return 1.0f + 0.15f * std::sin(7.0f * theta + phase_a) * std::sin(5.0f * phi + phase_b);
}

}  // namespace glslppm
