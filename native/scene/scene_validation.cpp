#include "scene/scene_validation.h"

#include <cmath>
#include <algorithm>
#include <cstdio>
#include <string>

namespace glslppm {
namespace {

constexpr float kPi = 3.14159265358979f;

std::string number(float v) {
    char text[32];
    std::snprintf(text, sizeof text, "%g", static_cast<double>(v));
    return text;
}

bool finite(glm::vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

bool finite(const glm::mat4& m) {
    for (int c = 0; c < 4; ++c)
        if (!finite(glm::vec3(m[c])) || !std::isfinite(m[c].w)) return false;
    return true;
}

// Field checks; `name` is the full path of the value, e.g. "lights[2].power".
struct Checker {
    [[noreturn]] static void fail(const std::string& name, const std::string& what) {
        throw SceneError(name + ": " + what);
    }
    static void non_negative(const std::string& name, float v) {
        if (!std::isfinite(v)) fail(name, number(v) + " is not a finite number");
        if (v < 0.0f) fail(name, number(v) + " is negative");
    }
    static void positive(const std::string& name, float v) {
        if (!std::isfinite(v) || !(v > 0.0f)) fail(name, number(v) + " is not a positive number");
    }
    static void in_range(const std::string& name, float v, float lo, float hi, bool open_lo,
                         bool open_hi, const std::string& range) {
        const bool ok = std::isfinite(v) && (open_lo ? v > lo : v >= lo) &&
                        (open_hi ? v < hi : v <= hi);
        if (!ok) fail(name, number(v) + " is outside " + range);
    }
    static void colour(const std::string& name, glm::vec3 c) {
        if (!finite(c)) fail(name, "has a NaN or infinite component");
        if (c.x < 0.0f || c.y < 0.0f || c.z < 0.0f) fail(name, "has a negative component");
    }
    static void point(const std::string& name, glm::vec3 p) {
        if (!finite(p)) fail(name, "has a NaN or infinite component");
    }
    static void matrix(const std::string& name, const glm::mat4& m) {
        if (!finite(m)) fail(name, "has a NaN or infinite entry");
    }
    static void texture_index(const std::string& name, std::int32_t k, std::size_t count) {
        if (k < -1 || k >= static_cast<std::int32_t>(count))
            fail(name, std::to_string(k) + " is not one of the scene's " +
                           std::to_string(count) + " textures");
    }
};

void validate_material(const Material& m, const std::string& name, std::size_t textures,
                       std::size_t materials) {
    if (static_cast<std::uint32_t>(m.kind) > static_cast<std::uint32_t>(MaterialKind::Mix))
        Checker::fail(name + ".kind", "is not a material kind");
    Checker::colour(name + ".color", m.color);
    Checker::colour(name + ".emission", m.emission);
    Checker::colour(name + ".f82_tint", m.f82_tint);
    Checker::colour(name + ".absorption", m.absorption);
    if (m.kind == MaterialKind::Dielectric || m.kind == MaterialKind::Plastic)
        Checker::positive(name + ".ior", m.ior);
    Checker::texture_index(name + ".color_texture", m.color_texture, textures);
    Checker::in_range(name + ".roughness", m.roughness, 0.0f, 1.0f, false, false, "[0, 1]");
    Checker::texture_index(name + ".roughness_texture", m.roughness_texture, textures);
    Checker::texture_index(name + ".normal_texture", m.normal_texture, textures);
    Checker::texture_index(name + ".bump_texture", m.bump_texture, textures);
    Checker::texture_index(name + ".emission_texture", m.emission_texture, textures);
    if (m.normal_texture >= 0 && m.bump_texture >= 0)
        Checker::fail(name + ".bump_texture", "is set beside normal_texture: a material has "
                                              "one or the other");
    Checker::in_range(name + ".bump_strength", m.bump_strength, 0.0f, 1.0e3f, false, false,
                      "[0, 1000]");
    Checker::in_range(name + ".bump_distance", m.bump_distance, -1.0e4f, 1.0e4f, false, false,
                      "[-10000, 10000]");
    Checker::in_range(name + ".normal_strength", m.normal_strength, 0.0f, 1.0e3f, false, false,
                      "[0, 1000]");
    if (m.kind != MaterialKind::Mix) return;
    for (auto [field, k] : {std::pair{".mix_a", m.mix_a}, std::pair{".mix_b", m.mix_b}})
        if (k < 0 || k >= static_cast<std::int32_t>(materials))
            Checker::fail(name + field, std::to_string(k) + " is not one of the scene's " +
                                            std::to_string(materials) + " materials");
    Checker::in_range(name + ".mix_factor", m.mix_factor, 0.0f, 1.0f, false, false, "[0, 1]");
    Checker::texture_index(name + ".mix_texture", m.mix_texture, textures);
    if (m.mix_mode == MixFactor::Fresnel || m.mix_mode == MixFactor::LayerFresnel)
        Checker::positive(name + ".mix_ior", m.mix_ior);
    if (m.mix_mode == MixFactor::Facing)
        Checker::in_range(name + ".mix_ior", m.mix_ior, 0.0f, 1.0f, false, false, "[0, 1]");
}

// Mixes are resolved on the GPU by walking down from the triangle's material, at most
// kMaxMixDepth levels: the mix graph must be a tree (or DAG) that shallow.
void validate_mix_depth(const std::vector<Material>& materials) {
    std::vector<int> depth(materials.size(), -1);  // -1 unknown, -2 on the current walk
    auto walk = [&](auto&& self, std::size_t k) -> int {
        if (depth[k] >= 0) return depth[k];
        if (depth[k] == -2)
            Checker::fail("materials[" + std::to_string(k) + "]", "mixes itself (a cycle of Mix materials)");
        const Material& m = materials[k];
        if (m.kind != MaterialKind::Mix) return depth[k] = 0;
        depth[k] = -2;
        const int d = 1 + std::max(self(self, static_cast<std::size_t>(m.mix_a)),
                                   self(self, static_cast<std::size_t>(m.mix_b)));
        if (d > kMaxMixDepth)
            Checker::fail("materials[" + std::to_string(k) + "]",
                          "nests Mix materials " + std::to_string(d) + " deep (at most " +
                              std::to_string(kMaxMixDepth) + ")");
        return depth[k] = d;
    };
    for (std::size_t k = 0; k < materials.size(); ++k) walk(walk, k);
}

void validate_light(const Light& l, const std::string& name) {
    Checker::colour(name + ".color", l.color);
    Checker::non_negative(name + ".power", l.power);
    // Power times colour must stay a float: the emitter table sums it.
    if (!finite(l.color * l.power)) Checker::fail(name + ".power", "times its colour overflows");
    switch (l.kind) {
        case LightKind::Point:
        case LightKind::Spot:
            Checker::point(name + ".position", l.position);
            Checker::non_negative(name + ".radius", l.radius);
            if (l.kind == LightKind::Spot) {
                Checker::in_range(name + ".spot_size", l.spot_size, 0.0f, kPi, true, false,
                                  "(0, pi] radians");
                Checker::in_range(name + ".spot_blend", l.spot_blend, 0.0f, 1.0f, false, false,
                                  "[0, 1]");
            }
            break;
        case LightKind::Sun:
            Checker::in_range(name + ".angle", l.angle, 0.0f, kPi, false, true, "[0, pi) radians");
            break;
        case LightKind::Area:
            Checker::matrix(name + ".to_world", l.to_world);
            Checker::positive(name + ".size_x", l.size_x);
            if (l.shape == AreaShape::Rectangle || l.shape == AreaShape::Ellipse)
                Checker::positive(name + ".size_y", l.size_y);
            break;
    }
    if (l.kind == LightKind::Spot || l.kind == LightKind::Sun) {
        Checker::point(name + ".direction", l.direction);
        if (glm::length(l.direction) == 0.0f) Checker::fail(name + ".direction", "is zero");
    }
}

}  // namespace

void validate_camera(const Camera& c) {
    Checker::matrix("camera.to_world", c.to_world);
    if (c.projection == Projection::Perspective)
        Checker::in_range("camera.fov_x", c.fov_x, 0.0f, kPi, true, true, "(0, pi) radians");
    else
        Checker::positive("camera.ortho_scale", c.ortho_scale);
    if (!std::isfinite(c.shift_x) || !std::isfinite(c.shift_y))
        Checker::fail("camera.shift", "is not finite");
    Checker::non_negative("camera.aperture_radius", c.aperture_radius);
    if (c.aperture_radius > 0.0f) Checker::positive("camera.focus_distance", c.focus_distance);
    Checker::positive("camera.pixel_aspect", c.pixel_aspect);
    if (c.full_width != 0 || c.full_height != 0) {
        if (c.full_width < 1 || c.full_height < 1 || c.region_x < 0 || c.region_y < 0 ||
            c.region_x >= c.full_width || c.region_y >= c.full_height)
            Checker::fail("camera.region", "expected a corner inside a frame of positive size");
    }
}

namespace {

void validate_texture(const Texture& t, const std::string& name) {
    if (t.width < 1 || t.height < 1)
        Checker::fail(name, "'" + t.name + "' is " + std::to_string(t.width) + "x" +
                                std::to_string(t.height) + " pixels");
    const std::size_t texels = std::size_t(t.width) * std::size_t(t.height) * 4;
    const bool srgb = !t.srgb8.empty(), linear = !t.linear.empty();
    if (srgb == linear || (srgb ? t.srgb8.size() : t.linear.size()) != texels)
        Checker::fail(name, "'" + t.name + "' must hold exactly width x height x 4 values of one "
                                           "encoding");
}

// Every group index names a group of Scene::light_groups (or is -1); the stored photon's
// record word holds at most MAX_LIGHT_GROUPS (shaders/common/records.glsl).
void validate_light_groups(const Scene& scene) {
    const auto count = static_cast<std::int64_t>(scene.light_groups.size());
    if (count > MAX_LIGHT_GROUPS)
        Checker::fail("light_groups", std::to_string(count) + " groups; at most " +
                                          std::to_string(MAX_LIGHT_GROUPS) + " are supported");
    const auto check = [&](std::int32_t group, const std::string& name) {
        if (group < -1 || group >= count)
            Checker::fail(name, "light group " + std::to_string(group) +
                                    " is not -1 or one of the " + std::to_string(count) +
                                    " light_groups");
    };
    for (std::size_t k = 0; k < scene.materials.size(); ++k)
        check(scene.materials[k].light_group, "materials[" + std::to_string(k) + "].light_group");
    for (std::size_t k = 0; k < scene.lights.size(); ++k)
        check(scene.lights[k].light_group, "lights[" + std::to_string(k) + "].light_group");
    check(scene.world_light_group, "world_light_group");
}

// Light linking: the two tables have a row each for the same rows, at most
// MAX_LIGHT_LINK_ROWS; every material's row is one of them and every link set is below
// MAX_LIGHT_LINK_SETS (a mask's bits). Without tables every set and row is 0.
void validate_light_links(const Scene& scene) {
    const auto rows = static_cast<std::int64_t>(scene.light_link_receives.size());
    if (static_cast<std::int64_t>(scene.shadow_link_blocks.size()) != rows)
        Checker::fail("shadow_link_blocks",
                      std::to_string(scene.shadow_link_blocks.size()) +
                          " rows; light_link_receives has " + std::to_string(rows) +
                          " (one row each per receiver kind)");
    if (rows > MAX_LIGHT_LINK_ROWS)
        Checker::fail("light_link_receives", std::to_string(rows) + " rows; at most " +
                                                 std::to_string(MAX_LIGHT_LINK_ROWS));
    const auto check_set = [&](std::int32_t set, const std::string& name) {
        if (set < 0 || set >= (rows > 0 ? MAX_LIGHT_LINK_SETS : 1))
            Checker::fail(name, "link set " + std::to_string(set) +
                                    (rows > 0 ? " is not between 0 and " +
                                                    std::to_string(MAX_LIGHT_LINK_SETS - 1)
                                              : " needs light_link_receives (none: only 0)"));
    };
    for (std::size_t k = 0; k < scene.materials.size(); ++k) {
        const std::string name = "materials[" + std::to_string(k) + "]";
        check_set(scene.materials[k].light_link_set, name + ".light_link_set");
        const std::int32_t row = scene.materials[k].light_link_row;
        if (row < 0 || row >= std::max<std::int64_t>(rows, 1))
            Checker::fail(name + ".light_link_row",
                          "row " + std::to_string(row) + " is not one of the " +
                              std::to_string(rows) + " rows of light_link_receives");
    }
    for (std::size_t k = 0; k < scene.lights.size(); ++k)
        check_set(scene.lights[k].light_link_set,
                  "lights[" + std::to_string(k) + "].light_link_set");
}

}  // namespace

void validate_scene(const Scene& scene) {
    if (scene.materials.empty())
        throw SceneError("materials: the scene has no materials (at least one is needed)");
    for (std::size_t k = 0; k < scene.materials.size(); ++k)
        validate_material(scene.materials[k], "materials[" + std::to_string(k) + "]",
                          scene.textures.size(), scene.materials.size());
    validate_mix_depth(scene.materials);
    for (std::size_t k = 0; k < scene.lights.size(); ++k)
        validate_light(scene.lights[k], "lights[" + std::to_string(k) + "]");
    validate_camera(scene.camera);
    for (std::size_t k = 0; k < scene.textures.size(); ++k)
        validate_texture(scene.textures[k], "textures[" + std::to_string(k) + "]");
    Checker::colour("environment", scene.environment);
    Checker::texture_index("environment_texture", scene.environment_texture,
                           scene.textures.size());
    if (!finite(glm::mat4(scene.environment_to_world)))
        Checker::fail("environment_to_world", "has a NaN or infinite entry");
    validate_light_groups(scene);
    validate_light_links(scene);
}

}  // namespace glslppm
