#include "procedural/million_scene.h"

#include <algorithm>
#include <cmath>

#include "procedural/shapes.h"
#include "procedural/sphere_field_room.h"

namespace glslppm {

Scene make_million_scene(const MillionSceneOptions& options) {
    auto mesh = std::make_shared<OwnedMesh>();
    using V = glm::vec3;
    append_sphere_field_room(*mesh);

    // k x k spheres of about 4k triangles or more each, at most 8 x 8.
    const std::size_t target = std::max<std::size_t>(options.triangles, 64);
    const int k =
        std::clamp(static_cast<int>(std::sqrt(static_cast<double>(target) / 4096.0)), 1, 8);
    const std::size_t budget = target / static_cast<std::size_t>(k * k);
    const int rings = sphere_rings_for(budget);
    const float cell = 1.8f / static_cast<float>(k);
    for (int i = 0; i < k * k; ++i) {
        const auto id = static_cast<std::uint32_t>(i);
        const float radius = 0.4f * cell * (0.7f + 0.3f * hash01(options.seed, 4 * id));
        const float phase_a = 6.2831853f * hash01(options.seed, 4 * id + 1);
        const float phase_b = 6.2831853f * hash01(options.seed, 4 * id + 2);
        const V centre(-0.9f + cell * (static_cast<float>(i % k) + 0.5f), 1.2f * radius,
                       -0.9f + cell * (static_cast<float>(i / k) + 0.5f));
        Shape s = make_sphere(V(0.0f), 1.0f, rings, 2 * rings);
        for (V& p : s.positions) p = centre + radius * sphere_bump(p, phase_a, phase_b) * p;
        mesh->append(s.positions, s.triangles, 2);
    }

    Scene scene = make_scene(mesh);
    scene.materials = sphere_field_materials();
    scene.camera = sphere_field_camera();
    return scene;
}

}  // namespace glslppm
