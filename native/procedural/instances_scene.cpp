#include "procedural/instances_scene.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include "procedural/shapes.h"
#include "procedural/sphere_field_room.h"

namespace glslppm {
namespace {

// The room and the one instanced mesh, kept alive together by the Scene.
struct Meshes {
    OwnedMesh room, sphere;
};

}  // namespace

Scene make_instances_scene(std::size_t count, std::size_t triangles, std::uint32_t seed) {
    auto meshes = std::make_shared<Meshes>();
    using V = glm::vec3;
    append_sphere_field_room(meshes->room);
    const int rings = sphere_rings_for(std::max<std::size_t>(triangles, 24));
    Shape s = make_sphere(V(0.0f), 1.0f, rings, 2 * rings);
    for (V& p : s.positions) p *= sphere_bump(p, 0.0f, 0.0f);
    meshes->sphere.append(s.positions, s.triangles, 0);

    Scene scene;
    scene.mesh = meshes->room.view();
    scene.instance_meshes = {meshes->sphere.view()};
    scene.keepalive = meshes;
    scene.materials = sphere_field_materials();
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
    scene.camera = sphere_field_camera();
    return scene;
}

}  // namespace glslppm
