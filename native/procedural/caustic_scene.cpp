#include "procedural/caustic_scene.h"

#include <cmath>

#include "procedural/shapes.h"

namespace glslppm {
namespace {

// A camera at `eye` looking at `target` with +Y up (Camera looks down its local -Z).
glm::mat4 look_at(glm::vec3 eye, glm::vec3 target) {
    const glm::vec3 back = glm::normalize(eye - target);
    const glm::vec3 right = glm::normalize(glm::cross(glm::vec3(0, 1, 0), back));
    const glm::vec3 up = glm::cross(back, right);
    glm::mat4 m(1.0f);
    m[0] = glm::vec4(right, 0.0f);
    m[1] = glm::vec4(up, 0.0f);
    m[2] = glm::vec4(back, 0.0f);
    m[3] = glm::vec4(eye, 1.0f);
    return m;
}

}  // namespace

// Geometry of the focus: a ball lens of radius R and index n focuses at n R / (2 (n - 1))
// from its centre (0.75 for R = 0.5, n = 1.5). With the light at (-2.5, 2.5, 0) and the
// centre at (0, 0.5, 0), the axis meets the floor 0.8 from the centre, at (0.625, 0, 0):
// near the focus and just outside the sphere's footprint, on the camera's side.
Scene make_caustic_scene(const CausticSceneOptions& options) {
    auto mesh = std::make_shared<OwnedMesh>();
    const float r = options.light_radiance;
    std::vector<Material> materials = {
        {MaterialKind::Diffuse, glm::vec3(0.8f), 1.5f, glm::vec3(0.0f)},              // floor
        {MaterialKind::Diffuse, glm::vec3(0.6f, 0.6f, 0.7f), 1.5f, glm::vec3(0.0f)},  // wall
        {MaterialKind::Diffuse, glm::vec3(0.0f), 1.5f, glm::vec3(r), -1, false},      // light
        {MaterialKind::Dielectric, glm::vec3(1.0f), options.ior, glm::vec3(0.0f)},    // glass
    };
    using V = glm::vec3;
    append_shape(*mesh, make_quad(V(-3, 0, -2), V(-3, 0, 3), V(3, 0, 3), V(3, 0, -2)), 0);    // floor
    append_shape(*mesh, make_quad(V(-3, 0, -2), V(3, 0, -2), V(3, 3, -2), V(-3, 3, -2)), 1);  // back
    // A 0.25 x 0.25 quad facing down-right towards the sphere (normal along +x, -y).
    const V c(-2.5f, 2.5f, 0.0f), n = glm::normalize(V(2.5f, -2.0f, 0.0f));
    const V u(0, 0, 0.125f), w = 0.125f * glm::normalize(glm::cross(n, V(0, 0, 1)));
    // Counter-clockwise seen from the side the normal points to.
    Shape light = make_quad(c - u - w, c - u + w, c + u + w, c + u - w);
    if (glm::dot(light.normals[0], n) < 0.0f)
        light = make_quad(c - u - w, c + u - w, c + u + w, c - u + w);
    append_shape(*mesh, light, 2);
    const int rings = options.sphere_rings;
    append_shape(*mesh, make_sphere(V(0.0f, 0.5f, 0.0f), 0.5f, rings, 2 * rings), 3);

    Scene scene = make_scene(mesh);
    scene.materials = std::move(materials);
    scene.camera.to_world = look_at(V(0.6f, 2.2f, 3.4f), V(0.25f, 0.3f, 0.0f));
    scene.camera.fov_x = 0.8f;
    return scene;
}

}  // namespace glslppm
