#include "render/emitters.h"

#include <bit>
#include <cmath>

namespace glslppm {
namespace {

constexpr float kPi = 3.14159265358979f;

float as_float(int v) { return std::bit_cast<float>(v); }
float weight_of(glm::vec3 power) { return (power.x + power.y + power.z) / 3.0f; }

}  // namespace

SceneBounds scene_bounds(const PackedBvh& bvh) {
    SceneBounds b;
    if (bvh.node_count == 0) return b;
    b.lo = glm::vec3(bvh.nodes[0]);
    b.hi = glm::vec3(bvh.nodes[1]);
    return b;
}

EmitterTable build_emitters(const Scene& scene, const std::vector<Material>& materials,
                            const PackedBvh& bvh, const SceneBounds& bounds,
                            const EnvironmentMap* environment) {
    EmitterTable table;
    std::vector<std::array<glm::vec4, 4>> list;
    auto add = [&](EmitterKind kind, glm::vec3 a, glm::vec4 b, glm::vec3 c, glm::vec3 power) {
        if (!(weight_of(power) > 0.0f)) return;  // dark; bad values were rejected earlier
        list.push_back({glm::vec4(a, as_float(static_cast<int>(kind))), b, glm::vec4(c, 0.0f),
                        glm::vec4(power, 0.0f)});
        table.has[static_cast<int>(kind)] = true;
        table.total_power += power;
    };

    // Emissive triangles radiate L over their area: power pi L A from each side that emits.
    // The scene's own materials emit from both sides, as Cycles' mesh lights do, unless they
    // say otherwise; the materials after them are area lights' (render/area_lights.h),
    // one-sided as Blender's.
    for (std::uint32_t t = 0; t < bvh.triangle_count; ++t) {
        const int material = std::bit_cast<int>(bvh.triangles[3 * t].w);
        const glm::vec3 emission = materials[static_cast<std::size_t>(material)].emission;
        if (weight_of(emission) <= 0.0f) continue;
        const glm::vec3 v0(bvh.triangles[3 * t]), v1(bvh.triangles[3 * t + 1]),
            v2(bvh.triangles[3 * t + 2]);
        // In double: the cross product squares the edges (float overflows at 1e10 scale).
        const float area = static_cast<float>(
            0.5 * glm::length(glm::cross(glm::dvec3(v1 - v0), glm::dvec3(v2 - v0))));
        const bool two_sided = static_cast<std::size_t>(material) < scene.materials.size() &&
                               scene.materials[static_cast<std::size_t>(material)].emission_two_sided;
        const float sides = two_sided ? 2.0f : 1.0f;
        add(EmitterKind::Triangle, v0, glm::vec4(v1, two_sided ? 1.0f : 0.0f), v2,
            emission * (kPi * area * sides));
    }
    const float r = bounds.radius();
    for (const Light& light : scene.lights) {
        const glm::vec3 color = light.color * light.power;
        switch (light.kind) {
            case LightKind::Point:
                // A sphere of the light's radius (0: a point), radiating the power evenly.
                add(EmitterKind::Point, light.position, glm::vec4(0.0f, 0.0f, 0.0f, light.radius),
                    glm::vec3(0.0f), color);
                break;
            case LightKind::Spot: {
                // Intensity power / 4 pi inside the cone (not concentrated, as in Cycles);
                // the hard cone's power is that times its solid angle.
                const float cos_half = std::cos(0.5f * light.spot_size);
                const float solid_angle = 2.0f * kPi * (1.0f - cos_half);
                const float smooth = (1.0f - cos_half) * light.spot_blend;
                add(EmitterKind::Spot, light.position,
                    glm::vec4(glm::normalize(light.direction), cos_half),
                    glm::vec3(smooth, light.radius, light.spot_cosine ? 1.0f : 0.0f),
                    color * (solid_angle / (4.0f * kPi)));
                break;
            }
            case LightKind::Sun:
                // Irradiance E through the bounding disc, from directions within half the
                // angular diameter of the sun's direction.
                add(EmitterKind::Sun, glm::vec3(0.0f),
                    glm::vec4(glm::normalize(light.direction), std::cos(0.5f * light.angle)),
                    glm::vec3(0.0f), color * (kPi * r * r));
                break;
            case LightKind::Area:
                break;  // emissive triangles (render/area_lights.h), listed above
        }
    }
    // The environment radiates onto the bounding disc from every direction: power
    // pi r^2 * (integral of L over the sphere); a constant L gives 4 pi * pi r^2 * L.
    if (environment) {
        add(EmitterKind::Environment, glm::vec3(0.0f), glm::vec4(0.0f), glm::vec3(0.0f),
            environment->integral * (kPi * r * r));
    } else {
        add(EmitterKind::Environment, glm::vec3(0.0f), glm::vec4(0.0f), glm::vec3(0.0f),
            scene.environment * (4.0f * kPi * kPi * r * r));
    }

    if (list.empty())
        throw SceneError(
            "the scene has no lights: nothing emits (add a light, an emissive material or a "
            "world colour)");
    double total = 0.0;
    for (const auto& e : list) total += weight_of(glm::vec3(e[3]));
    double running = 0.0;
    for (std::size_t k = 0; k < list.size(); ++k) {
        const double p = weight_of(glm::vec3(list[k][3])) / total;
        running += p;
        list[k][2].w = k + 1 == list.size() ? 2.0f : static_cast<float>(running);
        list[k][3].w = static_cast<float>(p);
        for (const glm::vec4& v : list[k]) table.records.push_back(v);
    }
    table.count = list.size();
    return table;
}

}  // namespace glslppm
