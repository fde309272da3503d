// Instanced scenes for the two-level MTBVH tests: test meshes placed under rotations,
// non-uniform scales, mirrors (negative determinant) and translations up to 1e5, with their
// flattened copies (every instance's triangles in world space, ids instance by instance), and
// rays aimed at the instances.
#pragma once

#include <cstdint>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <memory>
#include <random>
#include <vector>

#include "bvh/two_level_bvh.h"
#include "bvh_test_scenes.h"

namespace glslppm::bvh_test {

struct InstancedScene {
    std::vector<std::unique_ptr<OwnedMesh>> owned;
    std::vector<ValidMesh> meshes;
    std::vector<Instance> instances;
    std::vector<std::uint32_t> id_base;  // flattened id of each instance's triangle 0
    OwnedMesh flattened;
};

// A random rotation, scale factors in [0.3, 3] per axis, every other instance mirrored
// along one axis, translated by `offset` plus a spread that grows with the count.
inline glm::mat4 random_transform(detail::Rng& rng, int index, const glm::vec3& offset,
                                  float spread) {
    using detail::uniform;
    glm::quat q(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    q = glm::normalize(q);
    glm::vec3 s(uniform(rng, 0.3f, 3.0f), uniform(rng, 0.3f, 3.0f), uniform(rng, 0.3f, 3.0f));
    if (index % 2 == 1) s[index / 2 % 3] = -s[index / 2 % 3];
    const glm::vec3 t =
        offset + spread * glm::vec3(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
    glm::mat4 m = glm::mat4_cast(q);
    for (int c = 0; c < 3; ++c) m[c] *= s[c];
    m[3] = glm::vec4(t, 1.0f);
    return m;
}

// `count` instances cycling through `meshes` (owned by the scene).
inline InstancedScene make_instanced_scene(std::vector<OwnedMesh> meshes, int count,
                                           std::uint32_t seed, const glm::vec3& offset) {
    detail::Rng rng(seed);
    InstancedScene s;
    for (OwnedMesh& m : meshes) {
        s.owned.push_back(std::make_unique<OwnedMesh>(std::move(m)));
        s.meshes.push_back(validate_mesh(s.owned.back()->view(), 1));
    }
    const float spread = 2.0f * std::cbrt(static_cast<float>(count));
    std::uint32_t base = 0;
    for (int i = 0; i < count; ++i) {
        Instance inst;
        inst.mesh = static_cast<std::uint32_t>(i) % static_cast<std::uint32_t>(meshes.size());
        inst.to_world = random_transform(rng, i, offset, count == 1 ? 0.0f : spread);
        s.instances.push_back(inst);
        s.id_base.push_back(base);
        const OwnedMesh& m = *s.owned[inst.mesh];
        const auto first_vertex = static_cast<std::uint32_t>(s.flattened.positions.size());
        for (const glm::vec3& p : m.positions)
            s.flattened.positions.push_back(glm::vec3(inst.to_world * glm::vec4(p, 1.0f)));
        for (const glm::uvec3& t : m.triangles) s.flattened.triangles.push_back(t + first_vertex);
        base += static_cast<std::uint32_t>(m.triangles.size());
    }
    return s;
}

// Half the rays aimed at a random point of a random triangle of a random instance, from a
// random point of the scene's box grown by half its size; the rest between two random points
// of that box. Every 16th has tmin > 0, every 16th (offset by 8) a finite tmax.
inline std::vector<Ray> make_instance_rays(const InstancedScene& s, std::size_t count,
                                           std::uint32_t seed) {
    using detail::uniform;
    detail::Rng rng(seed);
    Aabb box;
    for (const glm::vec3& p : s.flattened.positions) box.grow(p);
    const glm::vec3 lo = box.lo - 0.5f * box.extent(), hi = box.hi + 0.5f * box.extent();
    auto point = [&] {
        return glm::vec3(uniform(rng, lo.x, hi.x), uniform(rng, lo.y, hi.y),
                         uniform(rng, lo.z, hi.z));
    };
    std::vector<Ray> rays;
    for (std::size_t k = 0; k < count; ++k) {
        const glm::vec3 o = point();
        glm::vec3 target;
        if (k % 2 == 0) {
            const std::size_t tri = std::uniform_int_distribution<std::size_t>(
                0, s.flattened.triangles.size() - 1)(rng);
            const glm::uvec3 t = s.flattened.triangles[tri];
            float a = uniform(rng), b = uniform(rng);
            if (a + b > 1.0f) a = 1.0f - a, b = 1.0f - b;
            const glm::vec3* p = s.flattened.positions.data();
            target = p[t.x] + a * (p[t.y] - p[t.x]) + b * (p[t.z] - p[t.x]);
        } else {
            target = point();
        }
        Ray r{o, target - o, 0.0f, std::numeric_limits<float>::infinity()};
        if (k % 16 == 3) r.tmin = 0.25f;
        if (k % 16 == 11) r.tmax = 0.75f;
        rays.push_back(r);
    }
    return rays;
}

}  // namespace glslppm::bvh_test
