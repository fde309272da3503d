// The features step of prepare_scene: the programs' #defines, chosen from what the prepared
// scene uses, and the variant's name (render/scene_preparation.h). The defines keep one
// order (the program cache's key): geometry and lights, materials, outputs, sizes.
#include <algorithm>
#include <bit>
#include <cmath>

#include "render/scene_preparation.h"

namespace glslppm {
namespace {

// The defines and the variant's feature names as they are chosen.
struct Features {
    const RenderSettings& settings;
    PreparedScene& p;
    std::vector<std::string> names;
    bool smooth_specular = false;  // a conductor or dielectric is traced (rough ones too: light tracing then compiles but splats only after smooth bounces)

    // A scene feature: compiled where the scene uses it, and in the full variant.
    void feature(bool on, const char* define, const char* name) {
        if (!on && !settings.full_variant) return;
        add(define, name);
    }
    // Compiled as chosen, the full variant too.
    void add(const std::string& define, const std::string& name, const std::string& value = "1") {
        p.defines.push_back({define, value});
        if (!name.empty()) names.push_back(name);
    }
};

// Whether a triangle of the scene, placed once or instanced, has a conductor or a
// dielectric.
void traced_material_kinds(const Scene& scene, const PackedBvh& bvh, const PreparedScene& p,
                           bool& conductor, bool& dielectric) {
    const std::vector<Material>& materials = p.geometry.materials;
    for (std::uint32_t t = 0; t < bvh.triangle_count; ++t) {
        const auto kind =
            materials[static_cast<std::size_t>(std::bit_cast<int>(bvh.triangles[3 * t].w))].kind;
        conductor |= kind == MaterialKind::Conductor;
        dielectric |= kind == MaterialKind::Dielectric;
    }
    if (!p.instancing.two_level) return;
    for (const Instance& inst : scene.instances) {
        const MeshView& m = scene.instance_meshes[inst.mesh];
        std::uint32_t most = 0;
        for (std::uint32_t id : m.material_ids) most = std::max(most, id);
        for (std::uint32_t k = 0; k <= most; ++k) {
            const auto kind = materials[inst.material_offset + k].kind;
            conductor |= kind == MaterialKind::Conductor;
            dielectric |= kind == MaterialKind::Dielectric;
        }
    }
}

void geometry_and_light_features(const Scene& scene, const PackedBvh& bvh, Features& f) {
    const PreparedScene& p = f.p;
    bool conductor = false, dielectric = false;
    traced_material_kinds(scene, bvh, p, conductor, dielectric);
    f.smooth_specular = conductor || dielectric;
    f.feature(!(p.instancing.two_level ? p.two_level->normals : bvh.normals).empty(), "HAS_NORMALS",
              "normals");
    f.feature(
        scene.camera.projection == Projection::Perspective && scene.camera.aperture_radius > 0.0f,
        "HAS_DEPTH_OF_FIELD", "depth-of-field");
    f.feature(scene.camera.projection == Projection::Orthographic, "HAS_ORTHOGRAPHIC",
              "orthographic");
    f.feature(conductor, "HAS_CONDUCTOR", "conductor");
    f.feature(dielectric, "HAS_DIELECTRIC", "dielectric");
    f.feature(p.emitters.has[0], "HAS_TRIANGLE_EMITTERS", "area-lights");
    f.feature(p.emitters.has[1], "HAS_POINT_LIGHTS", "point-lights");
    f.feature(p.emitters.has[2], "HAS_SPOT_LIGHTS", "spot-lights");
    f.feature(p.emitters.has[3], "HAS_SUN_LIGHTS", "sun-lights");
    f.feature(p.emitters.has[4] || glm::length(scene.environment) > 0.0f, "HAS_ENVIRONMENT",
              "environment");
    // Point and spot lights of a radius are spheres that mirrors and glass show
    // (common/sphere_lights.glsl); the shader looks through the analytic lights' records.
    bool sphere_lights = false;
    for (const Light& light : scene.lights)
        sphere_lights |= (light.kind == LightKind::Point || light.kind == LightKind::Spot) &&
                         light.radius > 0.0f && light.power > 0.0f;
    if (sphere_lights && p.emitters.light_count > 0) {
        f.add("SPHERE_LIGHT_FIRST", "", std::to_string(p.emitters.first_light) + "u");
        f.add("SPHERE_LIGHT_RECORDS", "sphere-lights",
              std::to_string(p.emitters.light_count) + "u");
    }
}

void texture_and_material_features(const Scene& scene, Features& f) {
    PreparedScene& p = f.p;
    const TextureUse& use = p.textures;
    const std::vector<Material>& materials = p.geometry.materials;
    f.feature(use.materials, "HAS_TEXTURES", "textures");
    // Textures looked up at the surface's position (Generated and Object coordinates) need
    // its world position beside its uv (TexturePoint in common/textures.glsl).
    bool position_textures = false;
    for (std::size_t k = 0; k < scene.textures.size(); ++k)
        position_textures |= use.materials && use.used[k] && scene.textures[k].from_position;
    f.feature(position_textures, "HAS_POSITION_TEXTURES", "position-textures");
    f.feature(p.vertex_colors, "HAS_VERTEX_COLORS", "vertex-colors");
    f.feature(uses_normal_maps(p), "HAS_NORMAL_MAP", "normal-map");
    bool emission_texture = false;
    for (const Material& m : materials)
        emission_texture |= use.materials && m.emission_texture >= 0;
    f.feature(emission_texture, "HAS_EMISSION_TEXTURE", "emission-texture");
    // Blender 4.x's F82 tint on a metal: a conductor whose tint is not white. Without one the
    // conductor Fresnel is Schlick's alone (3.6% of a pass on the glossy Cornell box, H200).
    bool f82_tint = false;
    for (const Material& m : materials)
        f82_tint |= m.kind == MaterialKind::Conductor && m.f82_tint != glm::vec3(1.0f);
    f.feature(f82_tint, "HAS_F82_TINT", "f82-tint");
    // Beer-Lambert inside closed objects (shaders/common/absorption.glsl): a factor on the
    // segments that end on such an object's back face, in the eye and photon paths.
    bool absorption = false;
    for (const Material& m : materials) absorption |= m.absorption != glm::vec3(0.0f);
    f.feature(absorption, "HAS_ABSORPTION", "absorption");
    // The lobes beyond Lambert, mirror and smooth glass (shaders/common/lobes.glsl): every
    // material of the table counts (mixes reach materials no triangle names). llvmpipe runs
    // every case of the lobes' switches: without them the built-in Cornell box with only
    // Lambert walls ran its eye and photon stages 1.6-1.7x faster (256x256, 65536 photons).
    bool rough_lobes = false;
    for (const Material& m : materials) rough_lobes |= needs_rough_lobes(m);
    f.feature(rough_lobes, "HAS_ROUGH_LOBES", "rough-lobes");
    // An environment map replaces the constant world rather than adding code beside it:
    // compiled only where the scene has one, in the full variant too (with it, a scene lit by
    // a constant world rendered black there).
    if (use.environment) f.add("HAS_ENVIRONMENT_MAP", "environment-map");
}

// Light sampling at the visible points (shaders/common/light_sampling.glsl) is compiled only
// when asked for; its shadow rays skip the surfaces that cast no shadow (area lights,
// objects with shadow visibility off) where the scene has them.
void direct_light_features(Features& f) {
    PreparedScene& p = f.p;
    const RenderSettings& settings = f.settings;
    if (settings.direct_light != DirectLight::Photons) {
        f.add("DIRECT_LIGHT_SAMPLED", "");
        bool shadowless = settings.full_variant;
        for (std::uint32_t flags : p.geometry.flags)
            shadowless |= (flags & (kMaterialLightSurface | kMaterialCastsNoShadow |
                                    kMaterialMayBeTransparent)) != 0;
        if (shadowless) f.add("HAS_SHADOWLESS_SURFACES", "");
    }
    // Multiple importance sampling of emissive triangles (mesh emission, area lights) at
    // glossy visible points: where a BSDF-sampled ray can hit one and a glossy lobe held by a
    // visible point can send it: a conductor or a plastic's coat at or above the glossy
    // threshold (dielectrics are always followed; below the threshold the eye path follows
    // the lobe, and a plastic's visible point holds its diffuse base alone). Compiled in
    // where no visible point uses it, the BSDF ray's walk still cost the H200 8.5% on the
    // glossy Cornell box (198.1 -> 181.3 passes/s at 1920x1080). Not in the full variant,
    // and not with two levels (their triangles are numbered per mesh, and instanced meshes'
    // emission is not in the emitter table); elsewhere the programs stay as they were.
    bool glossy = false;
    for (const Material& m : p.geometry.materials)
        glossy |= (m.kind == MaterialKind::Conductor || m.kind == MaterialKind::Plastic) &&
                  ((m.roughness >= settings.glossy_threshold && m.roughness > 0.0f) ||
                   m.roughness_texture >= 0);
    if (settings.direct_light == DirectLight::Sampled && glossy &&
        p.emitters.has[static_cast<int>(EmitterKind::Triangle)] && !p.instancing.two_level) {
        append_triangle_map(p.emitters);
        f.add("HAS_EMITTER_MIS", "emitter-mis");
    }
}

// Outputs and methods, not scene features: the full variant leaves them as the settings say.
void output_and_method_defines(unsigned local_size, Features& f) {
    PreparedScene& p = f.p;
    const RenderSettings& settings = f.settings;
    if (p.instancing.two_level) f.add("GLSLPPM_INSTANCES", "instances");
    f.add(settings.rng == RngKind::Pcg ? "RNG_PCG" : "RNG_PAPER", "");
    f.add(settings.hash == HashMode::Exact ? "HASH_EXACT" : "HASH_STOCHASTIC", "");
    f.add("LOCAL_SIZE", "", std::to_string(local_size) + "u");
    f.add("RADIUS_STATS_THREADS", "", std::to_string(kRadiusStatsThreads) + "u");
    f.names.push_back("rng=" + to_string(settings.rng));
    f.names.push_back("hash=" + to_string(settings.hash));
    f.names.push_back("direct=" + to_string(settings.direct_light));
    if (settings.estimator == Estimator::Pppm) f.add("ESTIMATOR_PPPM", "estimator=pppm");
    // Render passes: the full variant too leaves them as asked.
    const PassLayout passes =
        pass_layout(settings.passes, settings.direct_light == DirectLight::Photons);
    for (const auto& d : pass_defines(passes)) p.defines.push_back(d);
    if (!passes.passes.empty()) {
        std::string names;
        for (RenderPass pass : passes.passes)
            names += (names.empty() ? "" : "+") + std::string(render_pass_info(pass).name);
        f.names.push_back("passes=" + names);
    }
    p.pass_layout = passes;
}

// Light tracing of caustics seen directly (shaders/common/light_tracing.glsl): where the
// setting is on and the scene has L S+ D E paths to trace, a mirror or glass. Left out (the
// gather keeps those paths, as before) where it is not supported yet: cut-outs (camera rays
// see through them, the connection's shadow ray would not), depth of field (no lens
// sampling), the light split's passes (its Caustics pass would miss the splats), and the full
// variant (a material edit must not switch the film's buffers). The shader takes only
// Lambert surfaces (light_traceable) and leaves photons on the others to the gather. The connection inverts the
// camera's frame by its transpose, so a frame with scale or shear (the add-on drops scale; a
// module user may not) is left to the gather too.
bool rigid_frame(const glm::mat4& m) {
    const glm::mat3 r(m);
    const glm::mat3 gram = glm::transpose(r) * r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            if (std::abs(gram[i][j] - (i == j ? 1.0f : 0.0f)) > 1e-4f) return false;
    return true;
}

void light_tracing_feature(const Scene& scene, Features& f) {
    PreparedScene& p = f.p;
    bool cut_outs = false;
    for (std::uint32_t flags : p.geometry.flags) cut_outs |= (flags & kMaterialMayBeTransparent) != 0;
    p.light_tracing = light_tracing_allowed(scene, f.settings) && f.smooth_specular && !cut_outs;
    if (p.light_tracing) f.add("HAS_LIGHT_TRACING", "light-tracing");
}

}  // namespace

bool light_tracing_allowed(const Scene& scene, const RenderSettings& settings) {
    const Camera& camera = scene.camera;
    const bool depth_of_field =
        camera.projection == Projection::Perspective && camera.aperture_radius > 0.0f;
    const bool photon_split =
        pass_layout(settings.passes, settings.direct_light == DirectLight::Photons).photon_split;
    return settings.light_tracing && !depth_of_field && rigid_frame(camera.to_world) &&
           !photon_split && !settings.full_variant;
}

bool light_tracing_expected(const Scene& scene, const RenderSettings& settings) {
    // Cut-outs: a Transparent leaf anywhere (every mix leaf is a material of the list, and
    // one that is Transparent is itself flagged kMaterialMayBeTransparent).
    bool specular = false, cut_outs = false;
    for (const Material& m : scene.materials) {
        specular |= m.kind == MaterialKind::Conductor || m.kind == MaterialKind::Dielectric;
        cut_outs |= m.kind == MaterialKind::Transparent;
    }
    return specular && !cut_outs && light_tracing_allowed(scene, settings);
}

void choose_features(const Scene& scene, const RenderSettings& settings, unsigned local_size,
                     const PackedBvh& bvh, PreparedScene& p) {
    Features f{settings, p, {}};
    geometry_and_light_features(scene, bvh, f);
    texture_and_material_features(scene, f);
    // Not features but outputs: the full variant leaves them as the settings say.
    if (settings.transparent) {
        f.add("FILM_TRANSPARENT", "transparent");
        if (settings.transparent_glass) f.add("FILM_TRANSPARENT_GLASS", "transparent-glass");
    }
    direct_light_features(f);
    output_and_method_defines(local_size, f);
    light_tracing_feature(scene, f);
    for (const std::string& name : f.names) p.variant += (p.variant.empty() ? "" : ",") + name;
}

}  // namespace glslppm
