#include "procedural/cornell_box.h"

#include <cmath>

#include "procedural/shapes.h"

namespace glslppm {

Scene make_cornell_box(const CornellBoxOptions& options) {
    auto mesh = std::make_shared<OwnedMesh>();
    std::vector<Material> materials = {
        {MaterialKind::Diffuse, glm::vec3(0.75f), 1.5f, glm::vec3(0.0f)},               // white
        {MaterialKind::Diffuse, glm::vec3(0.75f, 0.25f, 0.25f), 1.5f, glm::vec3(0.0f)}, // red
        {MaterialKind::Diffuse, glm::vec3(0.25f, 0.75f, 0.25f), 1.5f, glm::vec3(0.0f)}, // green
        // The ceiling light shines down only, as the paper's scene (2 cm below the ceiling).
        {MaterialKind::Diffuse, glm::vec3(0.0f), 1.5f, glm::vec3(options.light_radiance), -1,
         false},
        {MaterialKind::Conductor, glm::vec3(0.95f), 1.5f, glm::vec3(0.0f)},             // mirror
        {MaterialKind::Dielectric, glm::vec3(1.0f), 1.5f, glm::vec3(0.0f)},             // glass
    };
    if (options.glossy) {
        Material& gold = materials[4];
        gold.color = {1.0f, 0.766f, 0.336f};
        gold.schlick = true;
        gold.roughness = 0.3f;
        materials[5].roughness = 0.25f;  // frosted glass
        Material floor = materials[0];
        floor.kind = MaterialKind::Plastic;
        floor.roughness = 0.4f;
        materials.push_back(floor);
    }
    const std::uint32_t floor = options.glossy ? 6 : 0;
    using V = glm::vec3;
    append_shape(*mesh, make_quad(V(-1, 0, -1), V(-1, 0, 1), V(1, 0, 1), V(1, 0, -1)), floor);
    append_shape(*mesh, make_quad(V(-1, 2, -1), V(1, 2, -1), V(1, 2, 1), V(-1, 2, 1)), 0);  // ceiling
    append_shape(*mesh, make_quad(V(-1, 0, -1), V(1, 0, -1), V(1, 2, -1), V(-1, 2, -1)), 0);  // back
    append_shape(*mesh, make_quad(V(-1, 0, -1), V(-1, 2, -1), V(-1, 2, 1), V(-1, 0, 1)), 1);  // left
    append_shape(*mesh, make_quad(V(1, 0, -1), V(1, 0, 1), V(1, 2, 1), V(1, 2, -1)), 2);      // right
    const float l = 0.3f, y = 1.98f;
    append_shape(*mesh, make_quad(V(-l, y, -l), V(l, y, -l), V(l, y, l), V(-l, y, l)), 3);  // light
    const int rings = options.sphere_rings;
    if (options.mirror_sphere)
        append_shape(*mesh, make_sphere(V(-0.45f, 0.38f, -0.35f), 0.38f, rings, 2 * rings), 4);
    if (options.glass_sphere)
        append_shape(*mesh, make_sphere(V(0.45f, 0.38f, 0.3f), 0.38f, rings, 2 * rings), 5);

    Scene scene = make_scene(mesh);
    scene.materials = std::move(materials);
    scene.camera.to_world = glm::mat4(1.0f);
    scene.camera.to_world[3] = glm::vec4(0.0f, 1.0f, 4.0f, 1.0f);
    scene.camera.fov_x = 2.0f * std::atan(1.15f / 3.0f);
    return scene;
}

}  // namespace glslppm
