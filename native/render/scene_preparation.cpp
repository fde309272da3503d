#include "render/scene_preparation.h"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include <glm/gtc/packing.hpp>

#include "bvh/traverse_cpu.h"
#include "render/camera_ray.h"
#include "render/microfacet_tables.h"
#include "scene/scene_validation.h"
#include "scene/tangent_space.h"

namespace glslppm {
namespace {

std::uint32_t next_power_of_two(std::uint64_t v) {
    std::uint64_t p = 1;
    while (p < v) p <<= 1;
    return static_cast<std::uint32_t>(p);
}

// A texture without uvs is a warning; indices were checked by validate_scene.
TextureUse texture_use(const Scene& scene, bool has_uvs, std::vector<std::string>& warnings) {
    TextureUse use;
    use.used.assign(scene.textures.size(), false);
    for (std::size_t k = 0; k < scene.materials.size(); ++k) {
        const Material& m = scene.materials[k];
        bool warned = false;
        for (const int t : {m.color_texture, m.roughness_texture, m.mix_texture, m.normal_texture,
                            m.bump_texture, m.emission_texture}) {
            if (t < 0) continue;  // indices were checked by validate_scene
            if (!has_uvs) {
                if (!warned)
                    warnings.push_back("materials[" + std::to_string(k) + "] has a texture but "
                                       "the mesh has no uvs: its constant values are used instead");
                warned = true;
                continue;
            }
            use.used[static_cast<std::size_t>(t)] = true;
            use.materials = true;
        }
    }
    if (scene.environment_texture >= 0) {
        use.used[static_cast<std::size_t>(scene.environment_texture)] = true;
        use.environment = true;
    }
    return use;
}

}  // namespace

float frame_camera(const Camera& cam, const RenderSettings& settings, const PackedBvh& bvh,
                   const SceneBounds& bounds, FrameBlock& f, const TwoLevelBvh* two_level) {
    const float diagonal = glm::length(bounds.hi - bounds.lo);
    // The whole frame (larger than the image when the image is a render region).
    const bool region = cam.full_width > 0;
    if (region && (cam.region_x + settings.width > cam.full_width ||
                   cam.region_y + settings.height > cam.full_height))
        throw std::invalid_argument("camera region: the image (" +
                                    std::to_string(settings.width) + "x" +
                                    std::to_string(settings.height) + " at " +
                                    std::to_string(cam.region_x) + ", " +
                                    std::to_string(cam.region_y) + ") does not fit in the " +
                                    std::to_string(cam.full_width) + "x" +
                                    std::to_string(cam.full_height) + " frame");
    const int frame_width = region ? cam.full_width : settings.width;
    const int frame_height = region ? cam.full_height : settings.height;
    // The film's height over its width; pixels may be non-square.
    const float aspect = static_cast<float>(frame_height) * cam.pixel_aspect /
                         static_cast<float>(frame_width);
    const bool wide = static_cast<float>(frame_width) >=
                      static_cast<float>(frame_height) * cam.pixel_aspect;
    const float tan_x = std::tan(0.5f * cam.fov_x);
    const float tan_larger = wide ? tan_x : tan_x * aspect;
    f.camera_to_world = cam.to_world;
    glm::vec2 half_extent, shift;
    if (cam.projection == Projection::Orthographic) {
        // Blender's ortho_scale spans the larger image side.
        const float half_larger = 0.5f * cam.ortho_scale;
        const float half_x = wide ? half_larger : half_larger / aspect;
        half_extent = glm::vec2(half_x, half_x * aspect);
        shift = glm::vec2(2.0f * cam.shift_x * half_larger, 2.0f * cam.shift_y * half_larger);
    } else {
        half_extent = glm::vec2(tan_x, tan_x * aspect);
        shift = glm::vec2(2.0f * cam.shift_x * tan_larger, 2.0f * cam.shift_y * tan_larger);
    }
    // The automatic radius below looks through the whole frame, so that a region or a tile
    // of it gathers with the radius the whole frame's render would use.
    const glm::vec2 frame_half_extent = half_extent, frame_shift = shift;
    if (region) {
        // The window's half extent and centre in the frame's film coordinates ([-1, 1],
        // y up, row 0 at the top).
        const glm::vec2 frame(frame_width, frame_height);
        const glm::vec2 size(settings.width, settings.height);
        const glm::vec2 corner(cam.region_x, cam.region_y);
        const glm::vec2 centre((2.0f * corner.x + size.x) / frame.x - 1.0f,
                               1.0f - (2.0f * corner.y + size.y) / frame.y);
        shift = shift + half_extent * centre;
        half_extent = half_extent * size / frame;
    }
    f.film_half_extent = half_extent;
    f.film_shift = shift;
    f.frame_first_pixel = region ? static_cast<std::uint32_t>(cam.region_y) *
                                           static_cast<std::uint32_t>(frame_width) +
                                       static_cast<std::uint32_t>(cam.region_x)
                                 : 0u;
    f.frame_width = static_cast<std::uint32_t>(frame_width);
    f.frame_pixels = static_cast<std::uint32_t>(frame_width) * static_cast<std::uint32_t>(frame_height);
    f.orthographic = cam.projection == Projection::Orthographic ? 1u : 0u;
    f.aperture_radius = cam.aperture_radius;
    f.focus_distance = cam.focus_distance;
    // Automatic radius: two pixel footprints at the distance of what the camera sees (the
    // median hit distance of a 5x5 grid of rays through the film, cast as eye_trace casts
    // its camera rays: camera_ray.h), at most 5% of the scene's diagonal.
    float radius = settings.initial_radius;
    if (radius <= 0.0f) {
        const glm::vec3 eye(cam.to_world[3]);
        // The whole frame seen as a 5 x 5 image, through pixel centres, without the lens.
        FrameBlock whole = f;
        whole.film_half_extent = frame_half_extent;
        whole.film_shift = frame_shift;
        whole.image_width = whole.image_height = 5;
        std::vector<float> distances;
        for (int j = 0; j < 5; ++j) {
            for (int i = 0; i < 5; ++i) {
                Ray ray = camera_ray_at(whole, glm::vec2(i + 0.5f, j + 0.5f), glm::vec2(0.0f),
                                        false);
                ray.dir = glm::normalize(ray.dir);
                if (two_level) {
                    const InstanceHit hit = closest_hit(*two_level, ray);
                    if (hit.instance >= 0) distances.push_back(hit.t);
                } else {
                    const Hit hit = closest_hit(bvh, ray);
                    if (hit.triangle >= 0) distances.push_back(hit.t);
                }
            }
        }
        float distance = glm::length(bounds.center() - eye);
        if (!distances.empty()) {
            std::nth_element(distances.begin(), distances.begin() + distances.size() / 2,
                             distances.end());
            distance = distances[distances.size() / 2];
        }
        const float footprint =
            cam.projection == Projection::Orthographic
                ? cam.ortho_scale / static_cast<float>(std::max(frame_width, frame_height))
                : 2.0f * distance * tan_x / static_cast<float>(frame_width);
        radius = std::min(2.0f * footprint, 0.05f * diagonal);
        if (!(radius > 0.0f)) radius = 0.01f * diagonal;
        radius *= settings.radius_scale;
    }
    return radius;
}

PreparedScene prepare_scene(const Scene& scene, const RenderSettings& settings,
                            unsigned local_size, const CancelFlag* cancel, const PackedBvh* built,
                            std::size_t flatten_max_triangles) {
    validate(settings);
    validate_scene(scene);
    PreparedScene p;
    // Area lights join the geometry; textures count only where the mesh has uvs for them.
    p.geometry = with_area_lights(scene);
    SceneGeometry& geometry = p.geometry;
    p.instancing =
        plan_instancing(scene, geometry.materials, settings.instancing, flatten_max_triangles);
    const bool two_level = p.instancing.two_level;
    SceneBounds instanced_bounds;
    if (!scene.instances.empty())
        instanced_scene_bounds(geometry.mesh, scene, instanced_bounds.lo, instanced_bounds.hi);
    if (p.instancing.path == "flattened") {
        const std::shared_ptr<OwnedMesh> flat = flatten_instances(geometry.mesh, scene, true);
        geometry.owned = flat;
        geometry.mesh = flat->view();
    }
    bool has_uvs = !geometry.mesh.uvs.empty();
    std::vector<MeshView> instance_meshes;
    if (two_level) {
        instance_meshes = scene.instance_meshes;
        for (const MeshView& m : instance_meshes) has_uvs |= !m.uvs.empty();
    }
    p.textures = texture_use(scene, has_uvs, p.warnings);
    const TextureUse& use = p.textures;
    if (!use.materials) {  // no texture lookups: no uvs uploaded
        geometry.mesh.uvs = {};
        for (MeshView& m : instance_meshes) m.uvs = {};
    }
    // Vertex colours are uploaded only where a material multiplies them in; a mesh of such a
    // scene that has none is white. An earlier MTBVH packed without them is built again.
    bool mesh_colors = !geometry.mesh.colors.empty();
    for (const MeshView& m : instance_meshes) mesh_colors |= !m.colors.empty();
    bool material_colors = false;
    for (const Material& m : geometry.materials) material_colors |= m.vertex_color;
    p.vertex_colors = mesh_colors && material_colors;
    if (!p.vertex_colors) {
        geometry.mesh.colors = {};
        for (MeshView& m : instance_meshes) m.colors = {};
    } else if (built && built->colors.empty()) {
        built = nullptr;
    }
    if (material_colors && !mesh_colors)
        p.warnings.push_back("a material multiplies in vertex colours but no mesh has any: "
                             "its colour is used alone");
    // Normal maps read each vertex's tangent: meshes without them get tangents from their
    // uvs (scene/tangent_space.h). An earlier MTBVH may lack them: it is built again. Bump
    // maps compile the same variant (they need no tangents; the normals they perturb are
    // packed with them).
    bool normal_map = false;
    for (const Material& m : geometry.materials)
        normal_map |= use.materials && (m.normal_texture >= 0 || m.bump_texture >= 0);
    if (normal_map) {
        built = nullptr;
        auto with_tangents = [&](MeshView& m) {
            if (!m.tangents.empty() || m.uvs.empty()) return;
            validate_mesh(m, static_cast<std::uint32_t>(geometry.materials.size()));  // indices
            p.generated_tangents.push_back(
                generate_tangents(m.positions, m.triangles, m.normals, m.uvs));
            m.tangents = p.generated_tangents.back();
        };
        with_tangents(geometry.mesh);
        for (MeshView& m : instance_meshes) with_tangents(m);
    }
    const auto material_count = static_cast<std::uint32_t>(geometry.materials.size());
    const ValidMesh mesh = validate_mesh(geometry.mesh, material_count);
    std::vector<ValidMesh> valid_instance_meshes;
    std::size_t kept = mesh.kept.size(), dropped = mesh.stats.degenerate_dropped;
    for (std::size_t m = 0; m < instance_meshes.size(); ++m) {
        try {
            valid_instance_meshes.push_back(validate_mesh(instance_meshes[m], material_count));
        } catch (const SceneError& e) {
            throw SceneError("instance_meshes[" + std::to_string(m) + "]: " + e.what());
        }
        dropped += valid_instance_meshes.back().stats.degenerate_dropped;
    }
    if (two_level)
        for (const Instance& inst : scene.instances)
            kept += valid_instance_meshes[inst.mesh].kept.size();
    if (kept == 0)
        throw SceneError("the scene has no geometry: nothing to render (" +
                         std::to_string(dropped) + " degenerate triangles dropped)");
    BvhBuildOptions options;
    options.leaf_size = settings.leaf_size;
    options.cancel = cancel;
    // Tables and camera change, the geometry did not: the earlier MTBVH stands (p.bvh stays
    // empty). Instanced scenes build their two levels again.
    if (two_level) built = nullptr;
    if (!built) p.bvh = build_packed_bvh(mesh, options, 6);
    const PackedBvh& bvh = built ? *built : p.bvh;
    if (two_level) {
        // Mesh 0: the placed-once triangles, under the identity; instance meshes after it.
        const auto bottom_start = std::chrono::steady_clock::now();
        std::vector<PackedBvh> bottoms;
        bottoms.push_back(p.bvh);
        for (const ValidMesh& m : valid_instance_meshes)
            bottoms.push_back(build_packed_bvh(m, options, 6));
        const double bottom_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - bottom_start).count();
        std::vector<Instance> instances{Instance{}};
        for (Instance inst : scene.instances) {
            ++inst.mesh;
            instances.push_back(inst);
        }
        p.two_level = std::make_unique<TwoLevelBvh>(build_two_level_bvh(bottoms, instances, options));
        p.two_level->stats.bottom_seconds = bottom_seconds;  // mesh 0 is timed in p.bvh.stats
    }
    p.bounds = scene.instances.empty() ? scene_bounds(bvh) : instanced_bounds;
    // float32 positions, radii and ray offsets hold from about 1e-14 to 1e11 units across
    // (tests/python/test_geometry_extremes.py): outside that, say so rather than render black.
    const double extent = glm::length(glm::dvec3(p.bounds.hi) - glm::dvec3(p.bounds.lo));
    if (!(extent >= 1e-14 && extent <= 1e11)) {
        char size[32];
        std::snprintf(size, sizeof size, "%.3g", extent);
        throw SceneError(std::string("the scene is ") + size +
                         " units across, outside the 1e-14 to 1e11 that 32-bit floats "
                         "render: scale it (Blender: the objects or the unit scale)");
    }
    if (use.environment) {
        p.environment = std::make_unique<EnvironmentMap>(build_environment_map(
            scene.textures[static_cast<std::size_t>(scene.environment_texture)],
            scene.environment));
    }
    throw_if_cancelled(cancel);
    p.emitters = build_emitters(scene, geometry.materials, bvh, p.bounds, p.environment.get());
    throw_if_cancelled(cancel);

    // The variant: only what this scene uses is compiled (DESIGN.md, "model only what a
    // scene requires").
    bool conductor = false, dielectric = false;
    for (std::uint32_t t = 0; t < bvh.triangle_count; ++t) {
        const auto kind = geometry.materials[static_cast<std::size_t>(
                                              std::bit_cast<int>(bvh.triangles[3 * t].w))]
                              .kind;
        conductor |= kind == MaterialKind::Conductor;
        dielectric |= kind == MaterialKind::Dielectric;
    }
    if (two_level) {
        for (const Instance& inst : scene.instances) {
            const MeshView& m = scene.instance_meshes[inst.mesh];
            std::uint32_t most = 0;
            for (std::uint32_t id : m.material_ids) most = std::max(most, id);
            for (std::uint32_t k = 0; k <= most; ++k) {
                const auto kind = geometry.materials[inst.material_offset + k].kind;
                conductor |= kind == MaterialKind::Conductor;
                dielectric |= kind == MaterialKind::Dielectric;
            }
        }
    }
    std::vector<std::string> features;
    auto feature = [&](bool on, const char* define, const char* name) {
        if (!on && !settings.full_variant) return;
        p.defines.push_back({define, "1"});
        features.push_back(name);
    };
    feature(!(two_level ? p.two_level->normals : bvh.normals).empty(), "HAS_NORMALS",
            "normals");
    feature(scene.camera.projection == Projection::Perspective && scene.camera.aperture_radius > 0.0f,
            "HAS_DEPTH_OF_FIELD", "depth-of-field");
    feature(scene.camera.projection == Projection::Orthographic, "HAS_ORTHOGRAPHIC", "orthographic");
    feature(conductor, "HAS_CONDUCTOR", "conductor");
    feature(dielectric, "HAS_DIELECTRIC", "dielectric");
    feature(p.emitters.has[0], "HAS_TRIANGLE_EMITTERS", "area-lights");
    feature(p.emitters.has[1], "HAS_POINT_LIGHTS", "point-lights");
    feature(p.emitters.has[2], "HAS_SPOT_LIGHTS", "spot-lights");
    feature(p.emitters.has[3], "HAS_SUN_LIGHTS", "sun-lights");
    feature(p.emitters.has[4] || glm::length(scene.environment) > 0.0f, "HAS_ENVIRONMENT",
            "environment");
    // Point and spot lights of a radius are spheres that mirrors and glass show
    // (common/sphere_lights.glsl); the shader looks through the analytic lights' records.
    bool sphere_lights = false;
    for (const Light& light : scene.lights)
        sphere_lights |= (light.kind == LightKind::Point || light.kind == LightKind::Spot) &&
                         light.radius > 0.0f && light.power > 0.0f;
    if (sphere_lights && p.emitters.light_count > 0) {
        p.defines.push_back({"SPHERE_LIGHT_FIRST", std::to_string(p.emitters.first_light) + "u"});
        p.defines.push_back({"SPHERE_LIGHT_RECORDS", std::to_string(p.emitters.light_count) + "u"});
        features.push_back("sphere-lights");
    }
    feature(use.materials, "HAS_TEXTURES", "textures");
    // Textures looked up at the surface's position (Generated and Object coordinates) need
    // its world position beside its uv (TexturePoint in common/textures.glsl).
    bool position_textures = false;
    for (std::size_t k = 0; k < scene.textures.size(); ++k)
        position_textures |= use.materials && use.used[k] && scene.textures[k].from_position;
    feature(position_textures, "HAS_POSITION_TEXTURES", "position-textures");
    feature(p.vertex_colors, "HAS_VERTEX_COLORS", "vertex-colors");
    // Materials read colours only where meshes have them; the full variant's programs (and
    // visible points) are laid out for them all the same.
    const bool colors_uploaded = p.vertex_colors;
    p.vertex_colors |= settings.full_variant;
    feature(normal_map, "HAS_NORMAL_MAP", "normal-map");
    bool emission_texture = false;
    for (const Material& m : geometry.materials)
        emission_texture |= use.materials && m.emission_texture >= 0;
    feature(emission_texture, "HAS_EMISSION_TEXTURE", "emission-texture");
    // Blender 4.x's F82 tint on a metal: a conductor whose tint is not white. Without one the
    // conductor Fresnel is Schlick's alone (3.6% of a pass on the glossy Cornell box, H200).
    bool f82_tint = false;
    for (const Material& m : geometry.materials)
        f82_tint |= m.kind == MaterialKind::Conductor && m.f82_tint != glm::vec3(1.0f);
    feature(f82_tint, "HAS_F82_TINT", "f82-tint");
    // Beer-Lambert inside closed objects (shaders/common/absorption.glsl): a factor on the
    // segments that end on such an object's back face, in the eye and photon paths.
    bool absorption = false;
    for (const Material& m : geometry.materials) absorption |= m.absorption != glm::vec3(0.0f);
    feature(absorption, "HAS_ABSORPTION", "absorption");
    // The lobes beyond Lambert, mirror and smooth glass (shaders/common/lobes.glsl): every
    // material of the table counts (mixes reach materials no triangle names). llvmpipe runs
    // every case of the lobes' switches: without them the built-in Cornell box with only
    // Lambert walls ran its eye and photon stages 1.6-1.7x faster (256x256, 65536 photons).
    bool rough_lobes = false;
    for (const Material& m : geometry.materials) rough_lobes |= needs_rough_lobes(m);
    feature(rough_lobes, "HAS_ROUGH_LOBES", "rough-lobes");
    p.material_records = material_records(geometry.materials, geometry.flags, use.materials,
                                          colors_uploaded);
    // An environment map replaces the constant world rather than adding code beside it:
    // compiled only where the scene has one, in the full variant too (with it, a scene lit by
    // a constant world rendered black there).
    if (use.environment) {
        p.defines.push_back({"HAS_ENVIRONMENT_MAP", "1"});
        features.push_back("environment-map");
    }
    // Not features but outputs: the full variant leaves them as the settings say.
    if (settings.transparent) {
        p.defines.push_back({"FILM_TRANSPARENT", "1"});
        features.push_back("transparent");
        if (settings.transparent_glass) {
            p.defines.push_back({"FILM_TRANSPARENT_GLASS", "1"});
            features.push_back("transparent-glass");
        }
    }
    // Light sampling at the visible points (shaders/common/light_sampling.glsl) is compiled
    // only when asked for; its shadow rays skip the surfaces that cast no shadow (area lights,
    // objects with shadow visibility off) where the scene has them.
    if (settings.direct_light != DirectLight::Photons) {
        p.defines.push_back({"DIRECT_LIGHT_SAMPLED", "1"});
        bool shadowless = settings.full_variant;
        for (std::uint32_t flags : geometry.flags)
            shadowless |= (flags & (kMaterialLightSurface | kMaterialCastsNoShadow |
                                    kMaterialMayBeTransparent)) != 0;
        if (shadowless) p.defines.push_back({"HAS_SHADOWLESS_SURFACES", "1"});
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
    for (const Material& m : geometry.materials)
        glossy |= (m.kind == MaterialKind::Conductor || m.kind == MaterialKind::Plastic) &&
                  ((m.roughness >= settings.glossy_threshold && m.roughness > 0.0f) ||
                   m.roughness_texture >= 0);
    if (settings.direct_light == DirectLight::Sampled && glossy &&
        p.emitters.has[static_cast<int>(EmitterKind::Triangle)] && !two_level) {
        append_triangle_map(p.emitters);
        p.defines.push_back({"HAS_EMITTER_MIS", "1"});
        features.push_back("emitter-mis");
    }
    if (two_level) {
        p.defines.push_back({"GLSLPPM_INSTANCES", "1"});
        features.push_back("instances");
    }
    p.defines.push_back({settings.rng == RngKind::Pcg ? "RNG_PCG" : "RNG_PAPER", "1"});
    p.defines.push_back({settings.hash == HashMode::Exact ? "HASH_EXACT" : "HASH_STOCHASTIC", "1"});
    p.defines.push_back({"LOCAL_SIZE", std::to_string(local_size) + "u"});
    p.defines.push_back({"RADIUS_STATS_THREADS", std::to_string(kRadiusStatsThreads) + "u"});
    features.push_back("rng=" + to_string(settings.rng));
    features.push_back("hash=" + to_string(settings.hash));
    features.push_back("direct=" + to_string(settings.direct_light));
    if (settings.estimator == Estimator::Pppm) {
        p.defines.push_back({"ESTIMATOR_PPPM", "1"});
        features.push_back("estimator=pppm");
    }
    // Render passes: outputs, not features, so the full variant too leaves them as asked.
    const PassLayout passes =
        pass_layout(settings.passes, settings.direct_light == DirectLight::Photons);
    for (const auto& d : pass_defines(passes)) p.defines.push_back(d);
    if (!passes.passes.empty()) {
        std::string names;
        for (RenderPass pass : passes.passes)
            names += (names.empty() ? "" : "+") + std::string(render_pass_info(pass).name);
        features.push_back("passes=" + names);
    }
    p.pass_layout = passes;
    for (const std::string& f : features) p.variant += (p.variant.empty() ? "" : ",") + f;

    // Sizes and the frame constants.
    p.pixels = static_cast<std::uint32_t>(settings.width) * static_cast<std::uint32_t>(settings.height);
    p.photon_threads = settings.photons_per_pass;
    p.hash_cells = next_power_of_two(std::max<std::uint64_t>(2ull * p.photon_threads, 1024));
    const float diagonal = glm::length(p.bounds.hi - p.bounds.lo);
    FrameBlock& f = p.frame;
    p.initial_radius = frame_camera(scene.camera, settings, bvh, p.bounds, f, p.two_level.get());
    f.scene_lo = p.bounds.lo;
    f.ray_offset_floor = 1e-3f * diagonal;
    f.scene_center = p.bounds.center();
    f.scene_radius = p.bounds.radius();
    f.world_radiance = scene.environment;
    f.environment_from_world = glm::mat4(glm::transpose(scene.environment_to_world));
    if (p.environment) {
        f.environment_texture = scene.environment_texture;
        f.environment_cdf_width = p.environment->width;
        f.environment_cdf_height = p.environment->height;
    }
    f.image_width = static_cast<std::uint32_t>(settings.width);
    f.image_height = static_cast<std::uint32_t>(settings.height);
    f.photon_threads = p.photon_threads;
    f.hash_cell_count = p.hash_cells;
    f.max_bounces = static_cast<std::uint32_t>(settings.max_bounces);
    f.max_diffuse_bounces = static_cast<std::uint32_t>(settings.max_diffuse_bounces);
    f.max_glossy_bounces = static_cast<std::uint32_t>(settings.max_glossy_bounces);
    f.max_transmission_bounces = static_cast<std::uint32_t>(settings.max_transmission_bounces);
    f.glossy_threshold = settings.glossy_threshold;
    f.shadow_terminator = settings.bump_shadowing == BumpShadowing::Conty2021 ? 1u : 0u;
    f.emitter_count = static_cast<std::uint32_t>(p.emitters.count);
    f.sppm_alpha = settings.alpha;
    f.radius_floor = 1e-5f * diagonal;
    return p;
}

}  // namespace glslppm
