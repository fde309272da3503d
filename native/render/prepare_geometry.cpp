// The geometry's steps of prepare_scene: validate, flatten or instance, tangents, BVH
// (render/scene_preparation.h).
#include <chrono>
#include <cstdio>
#include <stdexcept>

#include "render/scene_preparation.h"
#include "scene/scene_validation.h"
#include "scene/tangent_space.h"

namespace glslppm {
namespace {

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
                    warnings.push_back("materials[" + std::to_string(k) +
                                       "] has a texture but "
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

// Vertex colours are uploaded only where a material multiplies them in; a mesh of such a
// scene that has none is white.
void keep_used_vertex_colors(PreparedScene& p) {
    SceneGeometry& geometry = p.geometry;
    bool mesh_colors = !geometry.mesh.colors.empty();
    for (const MeshView& m : p.instance_meshes) mesh_colors |= !m.colors.empty();
    bool material_colors = false;
    for (const Material& m : geometry.materials) material_colors |= m.vertex_color;
    p.vertex_colors = mesh_colors && material_colors;
    if (!p.vertex_colors) {
        geometry.mesh.colors = {};
        for (MeshView& m : p.instance_meshes) m.colors = {};
    }
    if (material_colors && !mesh_colors)
        p.warnings.push_back(
            "a material multiplies in vertex colours but no mesh has any: "
            "its colour is used alone");
}

}  // namespace

void validate_inputs(const Scene& scene, const RenderSettings& settings) {
    validate(settings);
    validate_scene(scene);
}

void flatten_or_instance(const Scene& scene, const RenderSettings& settings,
                         std::size_t flatten_max_triangles, PreparedScene& p) {
    // Area lights join the geometry; textures count only where the mesh has uvs for them.
    p.geometry = with_area_lights(scene);
    SceneGeometry& geometry = p.geometry;
    std::shared_ptr<const MotionPlan> motion = plan_motion(scene);
    const bool instances_move = motion && (!motion->instances.empty() || !motion->meshes.empty());
    p.instancing = plan_instancing(scene, geometry.materials, settings.instancing,
                                   flatten_max_triangles, instances_move);
    p.instance_count = scene.instances.size();
    if (!scene.instances.empty())
        instanced_scene_bounds(geometry.mesh, scene, p.bounds.lo, p.bounds.hi);
    if (instances_move) grow_bounds_over_motion(scene, *motion, p.bounds.lo, p.bounds.hi);
    const bool placed_once = p.instancing.placed_once;
    if (p.instancing.path == "flattened" || placed_once) {
        // Placed once: every instance, or (moving instances, some emitting) the emitting ones,
        // whose motion then rewrites their triangles per pass.
        std::vector<std::int64_t> first;
        const std::shared_ptr<OwnedMesh> flat = flatten_instances(
            geometry.mesh, scene, true, placed_once ? &p.instancing.emitting : nullptr, &first);
        geometry.owned = flat;
        geometry.mesh = flat->view();
        if (placed_once) {
            bool deforms = false;
            for (const DeformMotion& d : motion->meshes)
                for (std::size_t i = 0; i < scene.instances.size(); ++i)
                    deforms |= p.instancing.emitting[i] && scene.instances[i].mesh == d.mesh;
            if (deforms)
                p.warnings.push_back("deformation blur of instances that emit light is not "
                                     "done: they move as rigid objects");
            motion = motion->with_emitters_placed_once(scene, p.instancing.emitting, first);
        }
    }
    p.motion = motion;
    bool has_uvs = !geometry.mesh.uvs.empty();
    if (p.instancing.two_level) {
        p.instance_meshes = scene.instance_meshes;
        p.traced_instances = scene.instances;
        if (placed_once) {
            const auto empty = static_cast<std::uint32_t>(p.instance_meshes.size());
            p.instance_meshes.emplace_back();
            for (std::size_t i = 0; i < p.traced_instances.size(); ++i)
                if (p.instancing.emitting[i]) p.traced_instances[i].mesh = empty;
        }
        for (const MeshView& m : p.instance_meshes) has_uvs |= !m.uvs.empty();
    }
    p.textures = texture_use(scene, has_uvs, p.warnings);
    if (!p.textures.materials) {  // no texture lookups: no uvs uploaded
        geometry.mesh.uvs = {};
        for (MeshView& m : p.instance_meshes) m.uvs = {};
    }
    keep_used_vertex_colors(p);
    p.geometry_triangles = geometry.mesh.triangles.size();
    p.material_count = geometry.materials.size();
}

// Bump maps compile the same variant (they need no tangents; the normals they perturb are
// packed with them).
bool uses_normal_maps(const PreparedScene& p) {
    bool normal_map = false;
    for (const Material& m : p.geometry.materials)
        normal_map |= p.textures.materials && (m.normal_texture >= 0 || m.bump_texture >= 0);
    return normal_map;
}

void generate_missing_tangents(PreparedScene& p) {
    if (!uses_normal_maps(p)) return;
    const auto material_count = static_cast<std::uint32_t>(p.geometry.materials.size());
    auto with_tangents = [&](MeshView& m) {
        if (!m.tangents.empty() || m.uvs.empty()) return;
        validate_mesh(m, material_count);  // indices
        p.generated_tangents.push_back(
            generate_tangents(m.positions, m.triangles, m.normals, m.uvs));
        m.tangents = p.generated_tangents.back();
    };
    with_tangents(p.geometry.mesh);
    for (MeshView& m : p.instance_meshes) with_tangents(m);
}

const PackedBvh& build_bvh(const Scene& scene, const RenderSettings& settings,
                           const CancelFlag* cancel, const PackedBvh* built, PreparedScene& p) {
    const bool two_level = p.instancing.two_level;
    const auto material_count = static_cast<std::uint32_t>(p.geometry.materials.size());
    const ValidMesh mesh = validate_mesh(p.geometry.mesh, material_count, cancel);
    std::vector<ValidMesh> valid_instance_meshes;
    std::size_t kept = mesh.kept.size(), dropped = mesh.stats.degenerate_dropped;
    for (std::size_t m = 0; m < p.instance_meshes.size(); ++m) {
        try {
            valid_instance_meshes.push_back(
                validate_mesh(p.instance_meshes[m], material_count, cancel));
        } catch (const SceneError& e) {
            throw SceneError("instance_meshes[" + std::to_string(m) + "]: " + e.what());
        }
        dropped += valid_instance_meshes.back().stats.degenerate_dropped;
    }
    if (two_level)
        for (const Instance& inst : p.traced_instances)
            kept += valid_instance_meshes[inst.mesh].kept.size();
    if (kept == 0)
        throw SceneError("the scene has no geometry: nothing to render (" +
                         std::to_string(dropped) + " degenerate triangles dropped)");
    BvhBuildOptions options;
    options.leaf_size = settings.leaf_size;
    options.cancel = cancel;
    if (!built) p.bvh = build_packed_bvh(mesh, options, 6);
    if (!built && p.motion) grow_over_area_light_motion(*p.motion, p.bvh);
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
        for (Instance inst : p.traced_instances) {
            ++inst.mesh;
            instances.push_back(inst);
        }
        p.two_level =
            std::make_unique<TwoLevelBvh>(build_two_level_bvh(bottoms, instances, options));
        p.two_level->stats.bottom_seconds = bottom_seconds;  // mesh 0 is timed in p.bvh.stats
    }
    if (scene.instances.empty()) p.bounds = scene_bounds(bvh);  // else flatten_or_instance's
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
    return bvh;
}

}  // namespace glslppm
