#include "scenes/million_scene.h"

#include <algorithm>
#include <cmath>

#include "scenes/shapes.h"

namespace glslppm {
namespace {

// A uniform float in [0, 1) from two integers (a 32-bit integer hash, splitmix-style), so
// that the scene does not depend on the standard library's distributions.
float hash01(std::uint32_t seed, std::uint32_t i) {
    std::uint32_t z = seed * 0x9E3779B9u + i * 0x85EBCA6Bu + 0x27D4EB2Fu;
    z = (z ^ (z >> 16)) * 0x7FEB352Du;
    z = (z ^ (z >> 15)) * 0x846CA68Bu;
    z ^= z >> 16;
    return static_cast<float>(z >> 8) * (1.0f / 16777216.0f);
}

// Rings of a latitude-longitude sphere (segments = 2 * rings) with about `budget` triangles:
// make_sphere gives 2 * rings * segments - 2 * segments = 4 r^2 - 4 r of them.
int rings_for(std::size_t budget) {
    const double r = 0.5 * (1.0 + std::sqrt(1.0 + static_cast<double>(budget)));
    return std::max(3, static_cast<int>(std::lround(r)));
}

}  // namespace

Scene make_million_scene(const MillionSceneOptions& options) {
    auto mesh = std::make_shared<OwnedMesh>();
    std::vector<Material> materials = {
        {MaterialKind::Diffuse, glm::vec3(0.75f), 1.5f, glm::vec3(0.0f)},             // room
        {MaterialKind::Diffuse, glm::vec3(0.0f), 1.5f, glm::vec3(17.0f)},             // light
        {MaterialKind::Diffuse, glm::vec3(0.7f, 0.5f, 0.3f), 1.5f, glm::vec3(0.0f)},  // spheres
    };
    using V = glm::vec3;
    for (const Shape& q : {make_quad(V(-1, 0, -1), V(-1, 0, 1), V(1, 0, 1), V(1, 0, -1)),
                           make_quad(V(-1, 2, -1), V(1, 2, -1), V(1, 2, 1), V(-1, 2, 1)),
                           make_quad(V(-1, 0, -1), V(1, 0, -1), V(1, 2, -1), V(-1, 2, -1)),
                           make_quad(V(-1, 0, -1), V(-1, 2, -1), V(-1, 2, 1), V(-1, 0, 1)),
                           make_quad(V(1, 0, -1), V(1, 0, 1), V(1, 2, 1), V(1, 2, -1))})
        mesh->append(q.positions, q.triangles, 0);
    const float l = 0.3f, y = 1.98f;
    const Shape light = make_quad(V(-l, y, -l), V(l, y, -l), V(l, y, l), V(-l, y, l));
    mesh->append(light.positions, light.triangles, 1);

    // k x k spheres of about 4k triangles or more each, at most 8 x 8.
    const std::size_t target = std::max<std::size_t>(options.triangles, 64);
    const int k =
        std::clamp(static_cast<int>(std::sqrt(static_cast<double>(target) / 4096.0)), 1, 8);
    const std::size_t budget = target / static_cast<std::size_t>(k * k);
    const int rings = rings_for(budget);
    const float cell = 1.8f / static_cast<float>(k);
    for (int i = 0; i < k * k; ++i) {
        const auto id = static_cast<std::uint32_t>(i);
        const float radius = 0.4f * cell * (0.7f + 0.3f * hash01(options.seed, 4 * id));
        const float phase_a = 6.2831853f * hash01(options.seed, 4 * id + 1);
        const float phase_b = 6.2831853f * hash01(options.seed, 4 * id + 2);
        const V centre(-0.9f + cell * (static_cast<float>(i % k) + 0.5f), 1.2f * radius,
                       -0.9f + cell * (static_cast<float>(i / k) + 0.5f));
        Shape s = make_sphere(V(0.0f), 1.0f, rings, 2 * rings);
        // Radial displacement r (1 + 0.15 sin(7 theta + a) sin(5 phi + b)) on the unit
        // sphere's (theta, phi), recovered from the undisplaced position.
        for (V& p : s.positions) {
            const float theta = std::acos(std::clamp(p.y, -1.0f, 1.0f));
            const float phi = std::atan2(p.z, p.x);
            const float bump =
                1.0f + 0.15f * std::sin(7.0f * theta + phase_a) * std::sin(5.0f * phi + phase_b);
            p = centre + radius * bump * p;
        }
        mesh->append(s.positions, s.triangles, 2);
    }

    Scene scene = make_scene(mesh);
    scene.materials = std::move(materials);
    // Looking down at the field from above the box's open front, so that most of the
    // spheres (and so most primary rays) are in view.
    const V eye(0.0f, 1.7f, 3.2f), back = glm::normalize(eye - V(0.0f, 0.35f, -0.1f));
    const V right = glm::normalize(glm::cross(V(0, 1, 0), back));
    scene.camera.to_world =
        glm::mat4(glm::vec4(right, 0.0f), glm::vec4(glm::cross(back, right), 0.0f),
                  glm::vec4(back, 0.0f), glm::vec4(eye, 1.0f));
    scene.camera.fov_x = 0.75f;
    return scene;
}

}  // namespace glslppm
