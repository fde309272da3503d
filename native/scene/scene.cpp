#include "scene/scene.h"

namespace glslppm {

void OwnedMesh::append(const std::vector<glm::vec3>& p, const std::vector<glm::uvec3>& t,
                       std::uint32_t material) {
    const auto base = static_cast<std::uint32_t>(positions.size());
    positions.insert(positions.end(), p.begin(), p.end());
    for (const glm::uvec3& tri : t) {
        triangles.push_back(tri + glm::uvec3(base));
        material_ids.push_back(material);
    }
}

void OwnedMesh::scale(float factor) {
    for (glm::vec3& p : positions) p *= factor;
}

Scene make_scene(std::shared_ptr<OwnedMesh> mesh) {
    Scene scene;
    scene.mesh = mesh->view();
    scene.keepalive = std::move(mesh);
    return scene;
}

}  // namespace glslppm
