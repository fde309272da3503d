// Each step of the scene's preparation on its own, without a GL context
// (render/scene_preparation.h): validate, flatten or instance, tangents, BVH, environment,
// emitters, features, camera and radius.
#include <gtest/gtest.h>

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <memory>
#include <string>

#include "bvh_test_scenes.h"
#include "procedural/cornell_box.h"
#include "render/scene_preparation.h"
#include "render/specializations.h"

namespace glslppm {
namespace {

RenderSettings small_settings() {
    RenderSettings s;
    s.width = 64;
    s.height = 48;
    s.photons_per_pass = 3000;
    return s;
}

bool has_define(const PreparedScene& p, const std::string& name) {
    for (const auto& [define, value] : p.defines)
        if (define == name) return true;
    return false;
}

// The Cornell box with a 12-triangle block placed twice as instances.
struct InstancedBox {
    std::shared_ptr<OwnedMesh> block = std::make_shared<OwnedMesh>();
    Scene scene = make_cornell_box();
    InstancedBox() {
        bvh_test::add_block(*block, glm::vec3(-0.1f), glm::vec3(0.1f));
        block->material_ids.assign(block->triangles.size(), 0u);
        scene.instance_meshes = {block->view()};
        for (float x : {-0.3f, 0.3f}) {
            Instance inst;
            inst.mesh = 0;
            inst.to_world = glm::translate(glm::mat4(1.0f), glm::vec3(x, 0.2f, 0.0f));
            scene.instances.push_back(inst);
        }
    }
};

// The Cornell box's mesh with uvs (from the positions) and a 1x1 normal map on material 0.
struct NormalMappedBox {
    std::shared_ptr<OwnedMesh> mesh = std::make_shared<OwnedMesh>();
    Scene scene = make_cornell_box();
    NormalMappedBox() {
        const MeshView& m = scene.mesh;
        mesh->positions.assign(m.positions.begin(), m.positions.end());
        mesh->triangles.assign(m.triangles.begin(), m.triangles.end());
        mesh->material_ids.assign(m.material_ids.begin(), m.material_ids.end());
        mesh->normals.assign(m.normals.begin(), m.normals.end());
        if (mesh->normals.empty()) mesh->normals.assign(mesh->positions.size(), glm::vec3(0, 0, 1));
        for (const glm::vec3& p : mesh->positions) mesh->uvs.emplace_back(p.x + p.z, p.y - p.z);
        scene.mesh = mesh->view();
        scene.keepalive = mesh;
        Texture t;
        t.name = "normal";
        t.width = t.height = 1;
        t.srgb8 = {128, 128, 255, 255};
        scene.textures.push_back(t);
        scene.materials[0].normal_texture = 0;
    }
};

TEST(PreparationSteps, ValidateNamesBadSettingsAndScenes) {
    EXPECT_NO_THROW(validate_inputs(make_cornell_box(), small_settings()));
    RenderSettings zero = small_settings();
    zero.width = 0;
    EXPECT_THROW(validate_inputs(make_cornell_box(), zero), std::invalid_argument);
    Scene scene = make_cornell_box();
    scene.lights.push_back(Light{});
    scene.lights.back().power = -1.0f;
    EXPECT_THROW(validate_inputs(scene, small_settings()), SceneError);
}

TEST(PreparationSteps, FlattenOrInstanceFollowsTheSetting) {
    const InstancedBox box;
    const std::size_t placed = box.scene.mesh.triangles.size();
    RenderSettings s = small_settings();
    s.instancing = Instancing::Flattened;
    PreparedScene flat;
    flatten_or_instance(box.scene, s, kFlattenMaxTrianglesSoftware, flat);
    EXPECT_EQ(flat.instancing.path, "flattened");
    EXPECT_TRUE(flat.instance_meshes.empty());
    EXPECT_EQ(flat.geometry_triangles, placed + 2 * 12);  // both copies in the geometry
    EXPECT_EQ(flat.instance_count, 2u);
    s.instancing = Instancing::TwoLevel;
    PreparedScene two;
    flatten_or_instance(box.scene, s, kFlattenMaxTrianglesSoftware, two);
    EXPECT_TRUE(two.instancing.two_level);
    ASSERT_EQ(two.instance_meshes.size(), 1u);
    EXPECT_EQ(two.geometry_triangles, placed);
    // The instanced bounds hold both blocks: x from -0.4 to 0.4 at least.
    EXPECT_LE(two.bounds.lo.x, -0.4f);
    EXPECT_GE(two.bounds.hi.x, 0.4f);
    // Neither textures nor vertex colours: no uvs or colours kept.
    EXPECT_FALSE(two.textures.materials);
    EXPECT_FALSE(two.vertex_colors);
    EXPECT_TRUE(two.instance_meshes[0].uvs.empty());
}

TEST(PreparationSteps, TangentsOnlyWhereANormalMapReadsThem) {
    PreparedScene plain;
    flatten_or_instance(make_cornell_box(), small_settings(), kFlattenMaxTrianglesSoftware, plain);
    EXPECT_FALSE(uses_normal_maps(plain));
    generate_missing_tangents(plain);
    EXPECT_TRUE(plain.generated_tangents.empty());
    EXPECT_TRUE(plain.geometry.mesh.tangents.empty());
    const NormalMappedBox box;
    PreparedScene mapped;
    flatten_or_instance(box.scene, small_settings(), kFlattenMaxTrianglesSoftware, mapped);
    EXPECT_TRUE(uses_normal_maps(mapped));
    generate_missing_tangents(mapped);
    ASSERT_EQ(mapped.generated_tangents.size(), 1u);
    // One tangent per vertex, unit length in xyz and a handedness of +-1 in w.
    ASSERT_EQ(mapped.geometry.mesh.tangents.size(), box.mesh->positions.size());
    for (const glm::vec4& t : mapped.geometry.mesh.tangents) {
        EXPECT_NEAR(glm::length(glm::vec3(t)), 1.0f, 1e-4f);
        EXPECT_EQ(std::abs(t.w), 1.0f);
    }
}

TEST(PreparationSteps, BvhHoldsEveryTriangleOrReusesTheEarlierOne) {
    const Scene scene = make_cornell_box();
    PreparedScene p;
    flatten_or_instance(scene, small_settings(), kFlattenMaxTrianglesSoftware, p);
    const PackedBvh& bvh = build_bvh(scene, small_settings(), nullptr, nullptr, p);
    EXPECT_EQ(&bvh, &p.bvh);
    EXPECT_EQ(bvh.triangle_count, scene.mesh.triangles.size());  // none degenerate
    EXPECT_EQ(bvh.order_count, 6);                               // an MTBVH
    for (const glm::vec3& v : scene.mesh.positions) {
        EXPECT_TRUE(glm::all(glm::lessThanEqual(p.bounds.lo, v)));
        EXPECT_TRUE(glm::all(glm::lessThanEqual(v, p.bounds.hi)));
    }
    PreparedScene again;
    flatten_or_instance(scene, small_settings(), kFlattenMaxTrianglesSoftware, again);
    EXPECT_EQ(&build_bvh(scene, small_settings(), nullptr, &p.bvh, again), &p.bvh);
    EXPECT_EQ(again.bvh.triangle_count, 0u);  // nothing built
    // Two levels: mesh 0 and the block, each instance a record.
    const InstancedBox box;
    RenderSettings s = small_settings();
    s.instancing = Instancing::TwoLevel;
    PreparedScene two;
    flatten_or_instance(box.scene, s, kFlattenMaxTrianglesSoftware, two);
    build_bvh(box.scene, s, nullptr, nullptr, two);
    ASSERT_TRUE(two.two_level);
    EXPECT_EQ(two.two_level->stats.mesh_triangles, scene.mesh.triangles.size() + 12);
}

TEST(PreparationSteps, EnvironmentDistributionOnlyWithAMap) {
    Scene scene = make_cornell_box();
    PreparedScene none;
    flatten_or_instance(scene, small_settings(), kFlattenMaxTrianglesSoftware, none);
    prepare_environment(scene, none);
    EXPECT_FALSE(none.environment);
    Texture sky;
    sky.name = "sky";
    sky.width = 4;
    sky.height = 2;
    sky.linear.assign(4 * 2 * 4, 1.0f);
    scene.textures.push_back(sky);
    scene.environment_texture = 0;
    scene.environment = glm::vec3(1.0f);
    PreparedScene p;
    flatten_or_instance(scene, small_settings(), kFlattenMaxTrianglesSoftware, p);
    prepare_environment(scene, p);
    ASSERT_TRUE(p.environment);
    const EnvironmentMap& e = *p.environment;
    // A marginal CDF over the rows, then one conditional CDF per row, each ending at 1.
    ASSERT_EQ(e.cdf.size(), std::size_t(e.height + 1 + e.height * (e.width + 1)));
    EXPECT_FLOAT_EQ(e.cdf[std::size_t(e.height)], 1.0f);
}

TEST(PreparationSteps, EmittersOfTheCornellBoxLight) {
    const Scene scene = make_cornell_box();
    PreparedScene p;
    flatten_or_instance(scene, small_settings(), kFlattenMaxTrianglesSoftware, p);
    const PackedBvh& bvh = build_bvh(scene, small_settings(), nullptr, nullptr, p);
    prepare_emitters(scene, bvh, p);
    EXPECT_EQ(p.emitters.count, 2u);  // the light's quad, two triangles
    EXPECT_TRUE(p.emitters.has[static_cast<int>(EmitterKind::Triangle)]);
    EXPECT_EQ(p.emitters.records.size(), 4 * p.emitters.count);
}

TEST(PreparationSteps, FeaturesFollowTheSceneAndTheFullVariantHasEveryOne) {
    CornellBoxOptions diffuse;
    diffuse.mirror_sphere = diffuse.glass_sphere = false;
    auto features = [&](const RenderSettings& s) {
        const Scene scene = make_cornell_box(diffuse);
        PreparedScene p;
        flatten_or_instance(scene, s, kFlattenMaxTrianglesSoftware, p);
        const PackedBvh& bvh = build_bvh(scene, s, nullptr, nullptr, p);
        prepare_emitters(scene, bvh, p);
        choose_features(scene, s, 64, bvh, p);
        return p;
    };
    const PreparedScene plain = features(small_settings());
    EXPECT_FALSE(has_define(plain, "HAS_LIGHT_TRACING"));  // no mirror, no glass
    EXPECT_FALSE(has_define(plain, "HAS_SPOT_LIGHTS"));
    EXPECT_TRUE(has_define(plain, "HAS_TRIANGLE_EMITTERS"));
    RenderSettings full = small_settings();
    full.full_variant = true;
    const PreparedScene all = features(full);
    // Every row of the table the full variant takes (render/specializations.h).
    int rows = 0;
    for (const Specialization& row : specializations()) {
        if (!row.in_full_variant) continue;
        EXPECT_TRUE(has_define(all, row.define)) << row.define;
        EXPECT_NE(all.variant.find(row.name), std::string::npos) << row.name;
        ++rows;
    }
    EXPECT_GE(rows, 15);
    // A benchmark forces one row into a scene that does not need it, and only that row.
    RenderSettings forced = small_settings();
    forced.forced_features = {"spot-lights"};
    const PreparedScene one = features(forced);
    EXPECT_TRUE(has_define(one, "HAS_SPOT_LIGHTS"));
    EXPECT_EQ(one.defines.size(), plain.defines.size() + 1);
    forced.forced_features = {"no-such-feature"};
    EXPECT_THROW(features(forced), std::invalid_argument);
    // The work-group size is every program's.
    bool local_size = false;
    for (const auto& [define, value] : all.defines)
        local_size |= define == "LOCAL_SIZE" && value == "64u";
    EXPECT_TRUE(local_size);
}

TEST(PreparationSteps, CameraFrameAndRadiusAgainstClosedForms) {
    Scene scene = make_cornell_box();
    const RenderSettings s = small_settings();
    FrameBlock f{};
    const WholeFilm film = camera_frame(scene.camera, s, f);
    const float tan_x = std::tan(0.5f * scene.camera.fov_x);
    EXPECT_FLOAT_EQ(f.film_half_extent.x, tan_x);
    EXPECT_FLOAT_EQ(f.film_half_extent.y, tan_x * 48.0f / 64.0f);
    EXPECT_EQ(film.width, 64);
    EXPECT_EQ(f.frame_pixels, 64u * 48u);
    PreparedScene p;
    flatten_or_instance(scene, s, kFlattenMaxTrianglesSoftware, p);
    const PackedBvh& bvh = build_bvh(scene, s, nullptr, nullptr, p);
    // Given: the radius as set.
    RenderSettings given = s;
    given.initial_radius = 0.125f;
    EXPECT_EQ(automatic_radius(scene.camera, given, f, film, bvh, p.bounds), 0.125f);
    // Orthographic: two pixel footprints, ortho_scale / the larger side, whatever is seen.
    scene.camera.projection = Projection::Orthographic;
    scene.camera.ortho_scale = 0.64f;
    const WholeFilm ortho = camera_frame(scene.camera, s, f);
    const float diagonal = glm::length(p.bounds.hi - p.bounds.lo);
    EXPECT_FLOAT_EQ(automatic_radius(scene.camera, s, f, ortho, bvh, p.bounds),
                    std::min(2.0f * 0.64f / 64.0f, 0.05f * diagonal));
    // The rest of the Frame: sizes and the scene-relative floors.
    PreparedScene whole = prepare_scene(make_cornell_box(), s, 64);
    EXPECT_EQ(whole.frame.hash_cell_count, 8192u);
    EXPECT_FLOAT_EQ(whole.frame.ray_offset_floor,
                    1e-3f * glm::length(whole.bounds.hi - whole.bounds.lo));
}

}  // namespace
}  // namespace glslppm
