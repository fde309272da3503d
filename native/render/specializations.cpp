#include "render/specializations.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace glslppm {
namespace {

using Inputs = FeatureInputs;

bool normals(const Inputs& in) {
    return !(in.p.instancing.two_level ? in.p.two_level->normals : in.bvh.normals).empty();
}
bool depth_of_field(const Inputs& in) {
    const Camera& c = in.scene.camera;
    return c.projection == Projection::Perspective && c.aperture_radius > 0.0f;
}
bool emits(const Inputs& in, EmitterKind kind) { return in.p.emitters.has[static_cast<int>(kind)]; }
bool triangle_emitters(const Inputs& in) { return emits(in, EmitterKind::Triangle); }
bool point_lights(const Inputs& in) { return emits(in, EmitterKind::Point); }
bool spot_lights(const Inputs& in) { return emits(in, EmitterKind::Spot); }
bool sun_lights(const Inputs& in) { return emits(in, EmitterKind::Sun); }
bool environment(const Inputs& in) {
    return emits(in, EmitterKind::Environment) || glm::length(in.scene.environment) > 0.0f;
}

// Point and spot lights of a radius are spheres that mirrors and glass show
// (common/sphere_lights.glsl); the shader looks through the analytic lights' records.
bool sphere_lights(const Inputs& in) {
    bool any = false;
    for (const Light& light : in.scene.lights)
        any |= (light.kind == LightKind::Point || light.kind == LightKind::Spot) &&
               light.radius > 0.0f && light.power > 0.0f;
    return any && in.p.emitters.light_count > 0;
}
std::vector<std::pair<std::string, std::string>> sphere_light_defines(const Inputs& in) {
    return {{"SPHERE_LIGHT_FIRST", std::to_string(in.p.emitters.first_light) + "u"},
            {"SPHERE_LIGHT_RECORDS", std::to_string(in.p.emitters.light_count) + "u"}};
}
bool has_analytic_lights(const Inputs& in) { return in.p.emitters.light_count > 0; }

// Light groups (docs/light_groups.md): the group count and the pass films' offset come with
// the pass layout (render_passes.cpp, pass_defines); the world's group is the eye stage's.
bool light_groups(const Inputs& in) { return !in.scene.light_groups.empty(); }
std::vector<std::pair<std::string, std::string>> light_group_defines(const Inputs& in) {
    return {{"LIGHT_GROUP_PASSES", "1"},
            {"WORLD_LIGHT_GROUP", std::to_string(in.scene.world_light_group)}};
}

// Light linking and shadow linking (docs/light_linking.md): the scene's two tables, as
// constant arrays the shaders index by a material's row (common/light_linking.glsl).
bool light_links(const Inputs& in) { return !in.scene.light_link_receives.empty(); }
std::string mask_list(const std::vector<std::uint32_t>& masks) {
    std::string list;
    for (std::uint32_t m : masks) list += (list.empty() ? "" : ",") + std::to_string(m) + "u";
    return list;
}
std::vector<std::pair<std::string, std::string>> light_link_defines(const Inputs& in) {
    return {{"LIGHT_LINKING", "1"},
            {"LIGHT_LINK_ROWS", std::to_string(in.scene.light_link_receives.size())},
            {"LIGHT_LINK_RECEIVES", mask_list(in.scene.light_link_receives)},
            {"SHADOW_LINK_BLOCKS", mask_list(in.scene.shadow_link_blocks)}};
}

bool textures(const Inputs& in) { return in.p.textures.materials; }
// Generated and Object coordinates: textures looked up at the world position beside the uv
// (TexturePoint in common/textures.glsl).
bool position_textures(const Inputs& in) {
    bool any = false;
    for (std::size_t k = 0; k < in.scene.textures.size(); ++k)
        any |=
            in.p.textures.materials && in.p.textures.used[k] && in.scene.textures[k].from_position;
    return any;
}
bool vertex_colors(const Inputs& in) { return in.p.vertex_colors; }
bool normal_maps(const Inputs& in) { return uses_normal_maps(in.p); }
bool emission_texture(const Inputs& in) {
    bool any = false;
    for (const Material& m : in.p.geometry.materials)
        any |= in.p.textures.materials && m.emission_texture >= 0;
    return any;
}
// Blender 4.x's F82 tint on a metal: a conductor whose tint is not white.
bool f82_tint(const Inputs& in) {
    bool any = false;
    for (const Material& m : in.p.geometry.materials)
        any |= m.kind == MaterialKind::Conductor && m.f82_tint != glm::vec3(1.0f);
    return any;
}
bool absorption(const Inputs& in) {
    bool any = false;
    for (const Material& m : in.p.geometry.materials) any |= m.absorption != glm::vec3(0.0f);
    return any;
}
// Every material of the table counts: mixes reach materials no triangle names.
bool rough_lobes(const Inputs& in) {
    bool any = false;
    for (const Material& m : in.p.geometry.materials) any |= needs_rough_lobes(m);
    return any;
}
bool environment_map(const Inputs& in) { return in.p.textures.environment; }

bool samples_lights(const Inputs& in) { return in.settings.direct_light != DirectLight::Photons; }
// Shadow rays skip the surfaces that cast no shadow (area lights, objects with shadow
// visibility off, cut-outs).
bool shadowless_surfaces(const Inputs& in) {
    if (!samples_lights(in)) return false;
    bool any = light_links(in);  // shadow linking's blockers pass shadow rays too
    for (std::uint32_t flags : in.p.geometry.flags)
        any |= (flags &
                (kMaterialLightSurface | kMaterialCastsNoShadow | kMaterialMayBeTransparent)) != 0;
    return any;
}
// Where a BSDF-sampled ray can hit an emissive triangle: light sampling and emissive
// triangles, whose BSDF sample every Lambertian or glossy visible point takes (issue 30:
// light samples by area miss a triangle's spike a millimetre away). Not with two levels:
// their triangles are numbered per mesh, and instanced meshes' emission is not in the table.
bool emitter_mis(const Inputs& in) {
    return in.settings.direct_light == DirectLight::Sampled && triangle_emitters(in) &&
           !in.p.instancing.two_level;
}

// A lobe the eye path follows and can evaluate: a metal, a glass or a plastic's coat of a
// roughness above 0 (or a roughness texture), whose vertex takes a light sample weighed
// against the continuation (common/glossy_light_samples.glsl). Not under VCM, whose eye
// subpaths are its own (common/vcm_eye_paths.glsl).
bool glossy_light_samples_apply(const Inputs& in) {
    return in.settings.direct_light == DirectLight::Sampled &&
           in.settings.estimator != Estimator::Vcm;
}
bool glossy_light_samples(const Inputs& in) {
    if (!glossy_light_samples_apply(in)) return false;
    bool any = false;
    for (const Material& m : in.p.geometry.materials)
        any |= (m.kind == MaterialKind::Conductor || m.kind == MaterialKind::Dielectric ||
                m.kind == MaterialKind::Plastic) &&
               (m.roughness > 0.0f || m.roughness_texture >= 0);
    return any;
}

// Where the settings and the camera allow it (light_tracing_allowed); the connection sees
// through cut-outs as camera rays do (common/light_tracing.glsl, camera_sees).
bool light_tracing_applies(const Inputs& in) {
    return light_tracing_allowed(in.scene, in.settings);
}
bool light_tracing(const Inputs& in) { return light_tracing_applies(in) && in.smooth_specular; }

bool two_level(const Inputs& in) { return in.p.instancing.two_level; }

using G = SpecializationGroup;

// The rows, in the programs' define order. `gain`: the pass time the row adds where a scene
// does not need it, by glslppm-bench specialize --each (the row forced into that scene's
// programs): on an H100 at 1920x1080 on cornell-diffuse / cornell / cornell-glossy, and on
// llvmpipe at 128^2 on cornell (docs/performance.md, "Each specialization's gain"; the
// bench's own spread, its control row, was 0.0-0.6% and 0.8%). Every row measured at
// least 1% on one of them, the bar for staying a compile-time choice.
const Specialization kRows[] = {
    {"normals", "HAS_NORMALS", "a mesh with vertex normals (smooth shading)",
     "every benchmark scene needs it: not measured alone", G::Scene, true, normals},
    {"depth-of-field", "HAS_DEPTH_OF_FIELD", "a perspective camera with an aperture",
     "H100 1080p +0.6% / +1.3% / +1.8%, llvmpipe 128^2 +0.4%", G::Scene, true, depth_of_field},
    {"area-lights", "HAS_TRIANGLE_EMITTERS", "emissive triangles (mesh emission, area lights)",
     "every benchmark scene needs it: not measured alone", G::Scene, true, triangle_emitters},
    {"point-lights", "HAS_POINT_LIGHTS", "a point light",
     "H100 1080p -0.6% / +1.2% / +1.5%, llvmpipe 128^2 +3.6%", G::Scene, true, point_lights},
    {"spot-lights", "HAS_SPOT_LIGHTS", "a spot light",
     "H100 1080p -0.7% / +1.2% / +1.3%, llvmpipe 128^2 -0.1%", G::Scene, true, spot_lights},
    {"sun-lights", "HAS_SUN_LIGHTS", "a sun light",
     "H100 1080p -0.5% / +1.1% / +1.3%, llvmpipe 128^2 -0.8%", G::Scene, true, sun_lights},
    {"environment", "HAS_ENVIRONMENT", "a world colour or map",
     "H100 1080p +20.2% / +26.7% / +17.3%, llvmpipe 128^2 +0.9%", G::Scene, true, environment},
    {"sphere-lights", "SPHERE_LIGHT_RECORDS", "a point or spot light with a radius",
     "not in the full variant: its define counts the scene's own light records", G::Scene, false,
     sphere_lights, has_analytic_lights, sphere_light_defines},
    {"textures", "HAS_TEXTURES", "an image texture on a material, on a mesh with uvs",
     "H100 1080p +7.0% / +8.9% / +13.9%, llvmpipe 128^2 +3.0%", G::Scene, true, textures},
    {"position-textures", "HAS_POSITION_TEXTURES", "a texture on Generated or Object coordinates",
     "H100 1080p -0.0% / +1.0% / +1.5%, llvmpipe 128^2 +2.4%", G::Scene, true, position_textures},
    {"vertex-colors", "HAS_VERTEX_COLORS", "a material that multiplies in vertex colours",
     "H100 1080p +2.2% / +4.7% / +1.7%, llvmpipe 128^2 +1.0%", G::Scene, true, vertex_colors},
    {"normal-map", "HAS_NORMAL_MAP", "a normal or bump map",
     "H100 1080p -2.4% / -7.7% / +15.5%, llvmpipe 128^2 -0.0%", G::Scene, true, normal_maps},
    {"emission-texture", "HAS_EMISSION_TEXTURE", "a texture on a material's emission",
     "H100 1080p -0.1% / +1.0% / +1.6%, llvmpipe 128^2 -0.7%", G::Scene, true, emission_texture},
    {"f82-tint", "HAS_F82_TINT", "a metal with a non-white F82 tint (Blender 4.x)",
     "H100 1080p -0.4% / +1.2% / +15.0%, llvmpipe 128^2 +0.4%; "
     "H200: 3.6% of a pass on the glossy Cornell box",
     G::Scene, true, f82_tint},
    {"absorption", "HAS_ABSORPTION", "glass with Beer-Lambert absorption",
     "H100 1080p -0.7% / +0.9% / +2.0%, llvmpipe 128^2 +1.4%", G::Scene, true, absorption},
    {"rough-lobes", "HAS_ROUGH_LOBES",
     "a lobe beyond Lambert, a mirror and smooth glass (rough, plastic, translucent, mix)",
     "H100 1080p +13.9% / +17.7% / needed, llvmpipe 128^2 +14.4%; "
     "llvmpipe: the Cornell box's eye and photon stages 1.6-1.7x faster without it",
     G::Scene, true, rough_lobes},
    {"environment-map", "HAS_ENVIRONMENT_MAP", "a world image",
     "not in the full variant: it replaces the constant world's code rather than adding to "
     "it (with it, a constant world rendered black)",
     G::Scene, false, environment_map, environment_map},
    {"shadowless-surfaces", "HAS_SHADOWLESS_SURFACES",
     "light sampling, and a surface that casts no shadow (area light, shadow visibility off, "
     "cut-out)",
     "H100 1080p +2.5% / +4.1% / +1.3%, llvmpipe 128^2 -2.4%", G::DirectLight, true,
     shadowless_surfaces, samples_lights},
    {"emitter-mis", "HAS_EMITTER_MIS", "light sampling and emissive triangles",
     "needed wherever it applies: not measured alone (before issue 30, where only glossy "
     "lobes took it: H100 1080p +11.8% / +16.1% / +1.9%, llvmpipe 128^2 +1.9%)",
     G::DirectLight, true, emitter_mis, emitter_mis},
    {"glossy-light-samples", "GLOSSY_LIGHT_SAMPLES",
     "light sampling, and a metal, glass or coat of a roughness the eye path follows",
     "needed wherever it applies (a sun's or a small lamp's highlight): not measured alone",
     G::DirectLight, true, glossy_light_samples, glossy_light_samples_apply},
    {"instances", "GLSLPPM_INSTANCES", "instances kept on two levels (Settings.instancing)",
     "not in the full variant: the geometry's buffers follow the instancing decision",
     G::DirectLight, false, two_level, two_level},
    {"light-groups", "LIGHT_GROUP_PASSES",
     "light groups (Scene.light_groups): a pass per group, photons and light samples carrying "
     "their emitter's group",
     "not measured yet (docs/light_groups.md); not in the full variant: it stands for the "
     "scene's groups, whose films the pass layout holds",
     G::Last, false, light_groups, light_groups, light_group_defines},
    {"light-linking", "LIGHT_LINKING",
     "light or shadow links (Scene.light_link_receives): light samples, emission met by BSDF "
     "samples and photons checked against the receiver's row, shadow rays against the "
     "blocker's",
     "not measured yet (docs/light_linking.md); not in the full variant: it stands for the "
     "scene's link tables",
     G::Last, false, light_links, light_links, light_link_defines},
    {"light-tracing", "HAS_LIGHT_TRACING",
     "a mirror or glass, with light tracing on (no light split)",
     "H100 1080p +40.6% on cornell-diffuse (the other scenes need it); "
     "H200: 14-29% fewer passes/s where it applies (the photon stage doubles); not in the "
     "full variant (a material edit must not switch the film's buffers)",
     G::Last, false, light_tracing, light_tracing_applies},
};

// The connection inverts the camera's frame by its transpose: a frame with scale or shear
// (the add-on drops scale; a module user may not) is left to the gather.
bool rigid_frame(const glm::mat4& m) {
    const glm::mat3 r(m);
    const glm::mat3 gram = glm::transpose(r) * r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            if (std::abs(gram[i][j] - (i == j ? 1.0f : 0.0f)) > 1e-4f) return false;
    return true;
}

}  // namespace

std::span<const Specialization> specializations() { return kRows; }

// The light split's passes (its Caustics pass would miss the splats), a camera frame with
// scale or shear, and the full variant (a material edit must not switch the film's buffers)
// rule light tracing out. With light groups each splat goes into its emitter's group's
// splats as well (common/light_splats.glsl). A thin lens
// connects through a point of its disc. With light links a photon splats only where it is
// stored, which its link decides (photon_trace.comp's stores_photon), as the gather's.
bool light_tracing_allowed(const Scene& scene, const RenderSettings& settings) {
    const Camera& camera = scene.camera;
    const bool photon_split =
        pass_layout(settings.passes, settings.direct_light == DirectLight::Photons).photon_split;
    return settings.light_tracing && rigid_frame(camera.to_world) && !photon_split &&
           !settings.full_variant;
}

bool light_tracing_expected(const Scene& scene, const RenderSettings& settings) {
    bool specular = false;
    for (const Material& m : scene.materials)
        specular |= m.kind == MaterialKind::Conductor || m.kind == MaterialKind::Dielectric;
    return specular && light_tracing_allowed(scene, settings);
}

bool traces_smooth_specular(const Scene& scene, const PackedBvh& bvh, const PreparedScene& p) {
    const std::vector<Material>& materials = p.geometry.materials;
    // A conductor or dielectric, or a mix with one among its leaves (a mirror cut-out).
    const auto specular = [&materials](std::int32_t m) {
        std::int32_t stack[16], top = 0;
        stack[top++] = m;
        while (top > 0) {
            const Material& k = materials[static_cast<std::size_t>(stack[--top])];
            if (k.kind == MaterialKind::Conductor || k.kind == MaterialKind::Dielectric)
                return true;
            if (k.kind == MaterialKind::Mix && top + 2 <= 16) {
                stack[top++] = k.mix_a;
                stack[top++] = k.mix_b;
            }
        }
        return false;
    };
    for (std::uint32_t t = 0; t < bvh.triangle_count; ++t)
        if (specular(std::bit_cast<int>(bvh.triangles[3 * t].w))) return true;
    if (!p.instancing.two_level) return false;
    for (const Instance& inst : scene.instances) {
        const MeshView& m = scene.instance_meshes[inst.mesh];
        std::uint32_t most = 0;
        for (std::uint32_t id : m.material_ids) most = std::max(most, id);
        for (std::uint32_t k = 0; k <= most; ++k)
            if (specular(static_cast<std::int32_t>(inst.material_offset + k))) return true;
    }
    return false;
}

}  // namespace glslppm
