// prepare_scene: the preparation's steps in their order (render/scene_preparation.h).
#include "render/scene_preparation.h"

namespace glslppm {

void prepare_environment(const Scene& scene, PreparedScene& p) {
    if (!p.textures.environment) return;
    p.environment = std::make_unique<EnvironmentMap>(build_environment_map(
        scene.textures[static_cast<std::size_t>(scene.environment_texture)], scene.environment));
}

void prepare_emitters(const Scene& scene, const PackedBvh& bvh, PreparedScene& p) {
    p.emitters = build_emitters(scene, p.geometry.materials, bvh, p.bounds, p.environment.get());
}

PreparedScene prepare_scene(const Scene& scene, const RenderSettings& settings, unsigned local_size,
                            const CancelFlag* cancel, const PackedBvh* built,
                            std::size_t flatten_max_triangles) {
    validate_inputs(scene, settings);
    PreparedScene p;
    flatten_or_instance(scene, settings, flatten_max_triangles, p);
    generate_missing_tangents(p);
    // Tables and camera changed, the geometry did not: the earlier MTBVH stands (p.bvh stays
    // empty), unless it lacks the vertex colours or tangents this scene uploads. Instanced
    // scenes build their two levels again.
    if (built && ((p.vertex_colors && built->colors.empty()) || uses_normal_maps(p) ||
                  p.instancing.two_level))
        built = nullptr;
    const PackedBvh& bvh = build_bvh(scene, settings, cancel, built, p);
    prepare_environment(scene, p);
    throw_if_cancelled(cancel);
    prepare_emitters(scene, bvh, p);
    throw_if_cancelled(cancel);
    choose_features(scene, settings, local_size, bvh, p);
    p.material_records = material_records(p.geometry.materials, p.geometry.flags,
                                          p.textures.materials, p.vertex_colors);
    // Materials read colours only where meshes have them; the full variant's programs (and
    // visible points) are laid out for them all the same.
    p.vertex_colors |= settings.full_variant;
    fill_frame(scene, settings, bvh, p);
    return p;
}

}  // namespace glslppm
