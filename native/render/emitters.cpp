#include "render/emitters.h"

#include "render/gpu_layout.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace glslppm {
namespace {

constexpr float kPi = 3.14159265358979f;

float as_float(int v) { return std::bit_cast<float>(v); }
float weight_of(glm::vec3 power) { return (power.x + power.y + power.z) / 3.0f; }

float srgb_to_linear(std::uint8_t v) {
    const float c = static_cast<float>(v) / 255.0f;
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

// A texel index along one axis of n texels under the texture's extension (Cycles'
// wrap_periodic, wrap_clamp, wrap_mirror); -1 for Clip outside the image.
int wrapped_texel(int i, int n, TextureWrap wrap) {
    switch (wrap) {
        case TextureWrap::Clip: return i < 0 || i >= n ? -1 : i;
        case TextureWrap::Extend: return std::clamp(i, 0, n - 1);
        case TextureWrap::Mirror: {
            const int m = std::abs(i + (i < 0 ? 1 : 0)) % (2 * n);
            return m >= n ? 2 * n - m - 1 : m;
        }
        default: return ((i % n) + n) % n;
    }
}

// A texel's linear rgb at mesh uv and world position p, nearest (the mean below needs no
// filtering).
glm::vec3 texel_at(const Texture& t, glm::vec2 mesh_uv, glm::vec3 p) {
    const glm::vec3 h(mesh_uv, 1.0f);
    const glm::vec4 q(p, 1.0f);
    const glm::vec2 uv =
        t.from_position ? glm::vec2(glm::dot(t.position_map_u, q), glm::dot(t.position_map_v, q))
                        : glm::vec2(glm::dot(t.uv_map_u, h), glm::dot(t.uv_map_v, h));
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return glm::vec3(0.0f);
    const auto index = [&](float c, int n) {
        // Repeat and Mirror are periodic over 2: reduce there first, so that the index stays
        // small; Clip and Extend read the same texel anywhere past the edges.
        c = t.wrap == TextureWrap::Repeat || t.wrap == TextureWrap::Mirror
                ? c - 2.0f * std::floor(0.5f * c)
                : std::clamp(c, -1.0f, 2.0f);
        const float f = std::floor(c * static_cast<float>(n));
        return wrapped_texel(static_cast<int>(f), n, t.wrap);
    };
    const int x = index(uv.x, t.width), y = index(uv.y, t.height);
    if (x < 0 || y < 0) return glm::vec3(0.0f);
    const std::size_t i = 4 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(t.width) +
                               static_cast<std::size_t>(x));
    if (!t.srgb8.empty())
        return {srgb_to_linear(t.srgb8[i]), srgb_to_linear(t.srgb8[i + 1]),
                srgb_to_linear(t.srgb8[i + 2])};
    return {t.linear[i], t.linear[i + 1], t.linear[i + 2]};
}

// The mean texel over a triangle's uvs: 16 x 16 stratified points, uniform in area. Only the
// emitter's pick probability reads it (photons and light samples weigh each point by its
// own texel over that probability), so an inexact mean costs noise, never bias; it is
// floored at 1e-3 of the brightest channel's untextured weight, so that a triangle whose
// bright texels fall between the points is still picked.
glm::vec3 mean_texel(const Texture& t, glm::vec2 w0, glm::vec2 w1, glm::vec2 w2, glm::vec3 p0,
                     glm::vec3 p1, glm::vec3 p2) {
    constexpr int n = 16;
    glm::vec3 sum(0.0f);
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            float a = (static_cast<float>(i) + 0.5f) / n, b = (static_cast<float>(j) + 0.5f) / n;
            if (a + b > 1.0f) {  // fold the square onto the triangle
                a = 1.0f - a;
                b = 1.0f - b;
            }
            sum +=
                texel_at(t, w0 + a * (w1 - w0) + b * (w2 - w0), p0 + a * (p1 - p0) + b * (p2 - p0));
        }
    }
    return sum / static_cast<float>(n * n);
}

// Each emitter's pick probability (its weight over the total) and the cumulative table
// pick_emitter searches (the last entry 2, above any u), into the records.
void write_pick_table(std::vector<GpuEmitter>& list, const std::vector<double>& weights,
                      EmitterTable& table) {
    double total = 0.0;
    for (const double w : weights) total += w;
    double running = 0.0;
    for (std::size_t k = 0; k < list.size(); ++k) {
        const double p = weights[k] / total;
        running += p;
        list[k].c.w = k + 1 == list.size() ? 2.0f : static_cast<float>(running);
        list[k].power.w = static_cast<float>(p);
        for (const glm::vec4& v : {list[k].a, list[k].b, list[k].c, list[k].power})
            table.records.push_back(v);
    }
    table.count = list.size();
}

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
    std::vector<GpuEmitter> list;
    std::vector<double> weights;  // what each emitter is picked by: its power
    // `power` is what the record holds (the shader's flux is power / pick probability);
    // `emitted`, where given, the power the emitter radiates on average (a textured one).
    // `group`: the emitter's light group (-1 none), whose code rides above the kind's bits.
    int group = -1;
    int link_set = 0;  // the emitter's light link set (docs/light_linking.md)
    auto add = [&](EmitterKind kind, glm::vec3 a, glm::vec4 b, glm::vec3 c, glm::vec3 power,
                   glm::vec3 emitted = glm::vec3(-1.0f)) {
        if (emitted.x < 0.0f) emitted = power;
        if (!(weight_of(emitted) > 0.0f)) return -1;  // dark; bad values were rejected earlier
        const int kind_word = static_cast<int>(kind) | (group + 1) << EMITTER_GROUP_SHIFT |
                              link_set << EMITTER_LINK_SHIFT;
        list.push_back(GpuEmitter{glm::vec4(a, as_float(kind_word)), b,
                                  glm::vec4(c, 0.0f), glm::vec4(power, 0.0f)});
        weights.push_back(weight_of(emitted));
        table.has[static_cast<int>(kind)] = true;
        table.total_power += emitted;
        return static_cast<std::int32_t>(list.size() - 1);
    };

    // Emissive triangles radiate L over their area: power pi L A from each side that emits.
    // The scene's own materials emit from both sides, as Cycles' emissive meshes do, unless they
    // say otherwise; the materials after them are area lights' (render/area_lights.h),
    // one-sided as Blender's.
    table.triangle_records.assign(bvh.triangle_count, -1);
    for (std::uint32_t t = 0; t < bvh.triangle_count; ++t) {
        const int material = std::bit_cast<int>(bvh.triangles[3 * t].w);
        const glm::vec3 emission = materials[static_cast<std::size_t>(material)].emission;
        if (weight_of(emission) <= 0.0f) continue;
        group = materials[static_cast<std::size_t>(material)].light_group;
        link_set = materials[static_cast<std::size_t>(material)].light_link_set;
        const glm::vec3 v0(bvh.triangles[3 * t]), v1(bvh.triangles[3 * t + 1]),
            v2(bvh.triangles[3 * t + 2]);
        // In double: the cross product squares the edges (float overflows at 1e10 scale).
        const float area = static_cast<float>(
            0.5 * glm::length(glm::cross(glm::dvec3(v1 - v0), glm::dvec3(v2 - v0))));
        const bool two_sided = static_cast<std::size_t>(material) < scene.materials.size() &&
                               scene.materials[static_cast<std::size_t>(material)].emission_two_sided;
        const float sides = two_sided ? 2.0f : 1.0f;
        const glm::vec3 power = emission * (kPi * area * sides);
        // A textured emitter (materials' emission_texture, where uvs are uploaded) holds its
        // untextured power and is picked by its mean: the shader weighs each point by its
        // texel, so that photons and light samples follow the image (emitters.glsl). b.w
        // then holds -(1 + 2 t + two_sided), exact in a float below 2^24.
        const int texture = materials[static_cast<std::size_t>(material)].emission_texture;
        if (texture >= 0 && !bvh.uvs.empty() && 2.0 * t + 2.0 < 16777216.0) {
            const glm::vec4 uv01 = bvh.uvs[2 * t], uv2 = bvh.uvs[2 * t + 1];
            const glm::vec3 mean =
                mean_texel(scene.textures[static_cast<std::size_t>(texture)], glm::vec2(uv01),
                           glm::vec2(uv01.z, uv01.w), glm::vec2(uv2), v0, v1, v2);
            const float floor = 1e-3f * std::max(power.x, std::max(power.y, power.z));
            const float code = -(1.0f + 2.0f * static_cast<float>(t) + (two_sided ? 1.0f : 0.0f));
            table.triangle_records[t] = add(EmitterKind::Triangle, v0, glm::vec4(v1, code), v2,
                                            power, glm::max(power * mean, glm::vec3(floor)));
            continue;
        }
        table.triangle_records[t] =
            add(EmitterKind::Triangle, v0, glm::vec4(v1, two_sided ? 1.0f : 0.0f), v2, power);
    }
    const float r = bounds.radius();
    table.first_light = list.size();
    table.light_records.assign(scene.lights.size(), -1);
    for (std::size_t index = 0; index < scene.lights.size(); ++index) {
        const Light& light = scene.lights[index];
        std::int32_t& record = table.light_records[index];
        const glm::vec3 color = light.color * light.power;
        group = light.light_group;
        link_set = light.light_link_set;
        switch (light.kind) {
            case LightKind::Point:
                // A sphere of the light's radius (0: a point), radiating the power evenly;
                // b.x 1: light samples take the disc facing the lit point (Light::facing_disc).
                record = add(EmitterKind::Point, light.position,
                    glm::vec4(light.facing_disc ? 1.0f : 0.0f, 0.0f, 0.0f, light.radius),
                    glm::vec3(0.0f), color);
                break;
            case LightKind::Spot: {
                // Intensity power / 4 pi inside the cone (not concentrated, as in Cycles);
                // the hard cone's power is that times its solid angle.
                const float cos_half = std::cos(0.5f * light.spot_size);
                const float solid_angle = 2.0f * kPi * (1.0f - cos_half);
                const float smooth = (1.0f - cos_half) * light.spot_blend;
                // c.z: 1 for Blender 3.x's cosine falloff, + 2 for the facing disc.
                const float code = float(light.spot_cosine) + 2.0f * float(light.facing_disc);
                record = add(EmitterKind::Spot, light.position,
                    glm::vec4(glm::normalize(light.direction), cos_half),
                    glm::vec3(smooth, light.radius, code), color * (solid_angle / (4.0f * kPi)));
                break;
            }
            case LightKind::Sun:
                // Irradiance E through the bounding disc, from directions within half the
                // angular diameter of the sun's direction.
                record = add(EmitterKind::Sun, glm::vec3(0.0f),
                    glm::vec4(glm::normalize(light.direction), std::cos(0.5f * light.angle)),
                    glm::vec3(0.0f), color * (kPi * r * r));
                break;
            case LightKind::Area:
                break;  // emissive triangles (render/area_lights.h), listed above
        }
    }
    table.light_count = list.size() - table.first_light;
    // The environment radiates onto the bounding disc from every direction: power
    // pi r^2 * (integral of L over the sphere); a constant L gives 4 pi * pi r^2 * L.
    group = scene.world_light_group;
    link_set = 0;
    const glm::vec3 world_power = environment ? environment->integral * (kPi * r * r)
                                              : scene.environment * (4.0f * kPi * kPi * r * r);
    add(EmitterKind::Environment, glm::vec3(0.0f), glm::vec4(0.0f), glm::vec3(0.0f), world_power);

    if (list.empty())
        throw SceneError(
            "the scene has no lights: nothing emits (add a light, an emissive material or a "
            "world colour)");
    write_pick_table(list, weights, table);
    return table;
}

void place_light(const Light& light, glm::vec4* record) {
    if (light.kind == LightKind::Point || light.kind == LightKind::Spot)
        record[0] = glm::vec4(light.position, record[0].w);
    if (light.kind == LightKind::Spot || light.kind == LightKind::Sun)
        record[1] = glm::vec4(glm::normalize(light.direction), record[1].w);
}

void append_triangle_map(EmitterTable& table) {
    const std::vector<std::int32_t>& map = table.triangle_records;
    for (std::size_t t = 0; t < map.size(); t += 4) {
        glm::vec4 v;
        for (std::size_t i = 0; i < 4; ++i)
            v[static_cast<int>(i)] = as_float(t + i < map.size() ? map[t + i] : -1);
        table.records.push_back(v);
    }
}

LightSplit light_split(const EmitterTable& table, float scene_radius) {
    LightSplit split;
    const auto luminance = [](glm::vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; };
    const float disc = kPi * scene_radius * scene_radius;
    double local = 0.0;
    glm::dvec3 moment1(0.0), moment2(0.0);
    for (std::size_t k = 0; k < table.count; ++k) {
        const glm::vec4* r = &table.records[k * EMITTER_VEC4];
        const int kind = std::bit_cast<std::int32_t>(r[EMITTER_A].w) & EMITTER_KIND_MASK;
        float power = luminance(glm::vec3(r[EMITTER_POWER]));
        // A spot's record holds its cone's power: as a point light's, 4 pi / Omega times it.
        if (kind == EMITTER_SPOT && r[EMITTER_B].w < 1.0f)
            power *= 2.0f / (1.0f - r[EMITTER_B].w);
        if (kind == EMITTER_ENVIRONMENT) {
            // power = pi R^2 times the integral of L over the sphere: pi mean(L) = power / 4 pi R^2.
            split.power.z += disc > 0.0f ? power / (4.0f * disc) : 0.0f;
            split.power.w += r[EMITTER_POWER].w;
        } else if (kind == EMITTER_SUN) {
            split.power.y += disc > 0.0f ? power / disc : 0.0f;  // power = E pi R^2
        } else {
            const glm::dvec3 at = kind == EMITTER_TRIANGLE
                ? (glm::dvec3(r[EMITTER_A]) + glm::dvec3(r[EMITTER_B]) + glm::dvec3(r[EMITTER_C])) / 3.0
                : glm::dvec3(r[EMITTER_A]);
            local += power;
            moment1 += double(power) * at;
            moment2 += double(power) * at * at;
        }
    }
    if (local > 0.0) {
        const glm::dvec3 centre = moment1 / local;
        const glm::dvec3 spread = moment2 / local - centre * centre;
        split.centre = glm::vec4(glm::vec3(centre),
                                 static_cast<float>(std::max(0.0, spread.x + spread.y + spread.z)));
        split.power.x = static_cast<float>(local);
    }
    return split;
}

}  // namespace glslppm
