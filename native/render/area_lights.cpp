#include "render/area_lights.h"

#include <cmath>
#include <string>

namespace glslppm {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr int kDiskSegments = 64;

// The light's outline in its local XY plane, counter-clockwise seen from -Z (its front).
std::vector<glm::vec2> outline(const Light& light) {
    const bool square = light.shape == AreaShape::Square || light.shape == AreaShape::Disk;
    const float a = 0.5f * light.size_x;
    const float b = 0.5f * (square ? light.size_x : light.size_y);
    std::vector<glm::vec2> points;
    if (light.shape == AreaShape::Square || light.shape == AreaShape::Rectangle) {
        points = {{-a, -b}, {-a, b}, {a, b}, {a, -b}};
    } else {
        for (int k = 0; k < kDiskSegments; ++k) {
            const float phi = -2.0f * kPi * static_cast<float>(k) / kDiskSegments;
            points.emplace_back(a * std::cos(phi), b * std::sin(phi));
        }
    }
    return points;
}

void check(const Light& light, std::size_t index) {
    const std::string name = "lights[" + std::to_string(index) + "]";
    if (!(light.size_x > 0.0f) || !(light.size_y > 0.0f) || !std::isfinite(light.size_x) ||
        !std::isfinite(light.size_y))
        throw SceneError(name + ": an area light's size must be positive and finite");
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            if (!std::isfinite(light.to_world[c][r]))
                throw SceneError(name + ": the area light's matrix holds NaN or Inf");
}

// Whether a material's mix tree reaches a Transparent leaf (alpha cut-outs): shadow rays
// then resolve it where they cross it. The mix graph was checked to be acyclic.
bool may_be_transparent(const std::vector<Material>& materials, const Material& m) {
    if (m.kind == MaterialKind::Transparent) return true;
    if (m.kind != MaterialKind::Mix) return false;
    return may_be_transparent(materials, materials[static_cast<std::size_t>(m.mix_a)]) ||
           may_be_transparent(materials, materials[static_cast<std::size_t>(m.mix_b)]);
}

}  // namespace

std::vector<glm::vec3> area_light_corners(const Light& light) {
    std::vector<glm::vec3> p;
    for (const glm::vec2& q : outline(light))
        p.emplace_back(light.to_world * glm::vec4(q, 0.0f, 1.0f));
    return p;
}

SceneGeometry with_area_lights(const Scene& scene) {
    SceneGeometry g;
    g.mesh = scene.mesh;
    g.materials = scene.materials;
    g.flags.reserve(g.materials.size());
    for (const Material& m : g.materials)
        g.flags.push_back((m.visible_to_camera ? 0u : kMaterialHiddenFromCamera) |
                          (m.emission_two_sided ? 0u : kMaterialOneSidedEmission) |
                          (m.casts_shadow ? 0u : kMaterialCastsNoShadow) |
                          (m.visible_in_reflections ? 0u : kMaterialHiddenFromReflections) |
                          (may_be_transparent(scene.materials, m) ? kMaterialMayBeTransparent : 0u));
    bool any = false;
    for (const Light& light : scene.lights) any |= light.kind == LightKind::Area;
    if (!any) return g;

    auto mesh = std::make_shared<OwnedMesh>();
    const MeshView& in = scene.mesh;
    mesh->positions.assign(in.positions.begin(), in.positions.end());
    mesh->triangles.assign(in.triangles.begin(), in.triangles.end());
    mesh->normals.assign(in.normals.begin(), in.normals.end());
    mesh->uvs.assign(in.uvs.begin(), in.uvs.end());
    mesh->tangents.assign(in.tangents.begin(), in.tangents.end());
    mesh->colors.assign(in.colors.begin(), in.colors.end());
    if (in.material_ids.empty())
        mesh->material_ids.assign(in.triangles.size(), 0u);
    else
        mesh->material_ids.assign(in.material_ids.begin(), in.material_ids.end());

    for (std::size_t index = 0; index < scene.lights.size(); ++index) {
        const Light& light = scene.lights[index];
        if (light.kind != LightKind::Area) continue;
        check(light, index);
        const std::vector<glm::vec3> p = area_light_corners(light);
        std::vector<glm::uvec3> t;
        float area = 0.0f;
        for (std::uint32_t k = 1; k + 1 < p.size(); ++k) {
            t.emplace_back(0u, k, k + 1);
            area += static_cast<float>(0.5 * glm::length(glm::cross(glm::dvec3(p[k] - p[0]),
                                                                     glm::dvec3(p[k + 1] - p[0]))));
        }
        if (!(area > 0.0f)) throw SceneError("lights[" + std::to_string(index) + "]: zero area");
        Material m;
        m.color = glm::vec3(0.0f);
        m.emission = light.color * (light.power / (kPi * area));
        m.light_group = light.light_group;
        m.light_link_set = light.light_link_set;
        const auto material = static_cast<std::uint32_t>(g.materials.size());
        g.materials.push_back(m);
        g.flags.push_back(kMaterialLightSurface |
                          (light.visible_to_camera ? 0u : kMaterialHiddenFromCamera));
        const glm::vec3 front = glm::normalize(glm::vec3(light.to_world * glm::vec4(0, 0, -1, 0)));
        if (!mesh->normals.empty()) mesh->normals.insert(mesh->normals.end(), p.size(), front);
        if (!mesh->uvs.empty()) mesh->uvs.insert(mesh->uvs.end(), p.size(), glm::vec2(0.0f));
        if (!mesh->tangents.empty())  // any tangent: a light has no normal map
            mesh->tangents.insert(mesh->tangents.end(), p.size(), glm::vec4(1, 0, 0, 1));
        if (!mesh->colors.empty())  // white: a light's material reads no vertex colour
            mesh->colors.insert(mesh->colors.end(), p.size(), glm::vec3(1.0f));
        mesh->append(p, t, material);
    }
    g.mesh = mesh->view();
    g.owned = std::move(mesh);
    return g;
}

}  // namespace glslppm
