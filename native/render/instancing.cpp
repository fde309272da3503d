#include "render/instancing.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace glslppm {
namespace {

std::size_t triangles_of(const MeshView& m) { return m.triangles.size(); }

std::uint32_t max_material(const MeshView& m) {
    std::uint32_t most = 0;
    for (std::uint32_t id : m.material_ids) most = std::max(most, id);
    return most;
}

bool emits(const Material& m) { return m.emission.x > 0 || m.emission.y > 0 || m.emission.z > 0; }

}  // namespace

InstancePlan plan_instancing(const Scene& scene, const std::vector<Material>& materials,
                             Instancing mode, std::size_t flatten_max_triangles,
                             bool instances_move) {
    InstancePlan plan;
    if (scene.instances.empty()) {
        plan.path = "none";
        plan.reason = "the scene has no instances";
        return plan;
    }
    std::vector<std::uint32_t> most(scene.instance_meshes.size());
    for (std::size_t m = 0; m < most.size(); ++m) most[m] = max_material(scene.instance_meshes[m]);
    bool emissive = false;
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        const Instance& inst = scene.instances[i];
        const std::string name = "instances[" + std::to_string(i) + "]";
        if (inst.mesh >= scene.instance_meshes.size())
            throw SceneError(name + ".mesh: " + std::to_string(inst.mesh) + " is out of range (" +
                             std::to_string(scene.instance_meshes.size()) + " instance meshes)");
        const glm::mat4& m = inst.to_world;
        bool finite = true;
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r) finite &= std::isfinite(m[c][r]);
        if (!finite) throw SceneError(name + ".to_world: not finite");
        if (m[0][3] != 0.0f || m[1][3] != 0.0f || m[2][3] != 0.0f || m[3][3] != 1.0f)
            throw SceneError(name + ".to_world: not affine (the bottom row must be 0 0 0 1)");
        if (!(std::abs(glm::determinant(glm::dmat3(glm::mat3(m)))) > 0.0))
            throw SceneError(name + ".to_world: singular (it flattens the mesh)");
        const std::uint64_t top = std::uint64_t(inst.material_offset) + most[inst.mesh];
        if (top >= materials.size())
            throw SceneError(name + ".material_offset: " + std::to_string(inst.material_offset) +
                             " puts material " + std::to_string(top) + " past the " +
                             std::to_string(materials.size()) + " materials");
        plan.instanced_triangles += triangles_of(scene.instance_meshes[inst.mesh]);
        bool lit = false;
        for (std::uint32_t k = 0; k <= most[inst.mesh] && !lit; ++k)
            lit = emits(materials[inst.material_offset + k]);
        plan.emitting.push_back(lit);
        emissive |= lit;
    }
    const auto emitting_count =
        static_cast<std::size_t>(std::count(plan.emitting.begin(), plan.emitting.end(), true));
    if (instances_move && emissive) {
        // Emitters are placed once (photons start from world-space triangles); the rest,
        // if any, move through the two levels.
        plan.placed_once = true;
        plan.path = emitting_count < scene.instances.size() ? "two-level" : "flattened";
        plan.reason = "instances move (motion blur); the " + std::to_string(emitting_count) +
                      " that emit light are placed once";
    } else if (instances_move) {
        plan.path = "two-level";
        plan.reason = "instances move (motion blur)";
    } else if (mode == Instancing::Flattened) {
        plan.path = "flattened";
        plan.reason = "asked for";
    } else if (emissive) {
        // Photons and light samples start from world-space emitter triangles.
        plan.path = "flattened";
        plan.reason = "instanced meshes emit light";
    } else if (mode == Instancing::TwoLevel) {
        plan.path = "two-level";
        plan.reason = "asked for";
    } else if (plan.instanced_triangles <= flatten_max_triangles) {
        plan.path = "flattened";
        plan.reason = std::to_string(plan.instanced_triangles) +
                      " instanced triangles <= " + std::to_string(flatten_max_triangles);
    } else {
        plan.path = "two-level";
        plan.reason = std::to_string(plan.instanced_triangles) + " instanced triangles > " +
                      std::to_string(flatten_max_triangles);
    }
    plan.two_level = plan.path == "two-level";
    return plan;
}

std::shared_ptr<OwnedMesh> flatten_instances(const MeshView& world, const Scene& scene,
                                             bool keep_uvs, const std::vector<bool>* only,
                                             std::vector<std::int64_t>* first_triangle) {
    auto out = std::make_shared<OwnedMesh>();
    bool normals = !world.normals.empty(), uvs = keep_uvs && !world.uvs.empty();
    bool tangents = !world.tangents.empty(), colors = !world.colors.empty();
    for (const MeshView& m : scene.instance_meshes) {
        normals |= !m.normals.empty();
        colors |= !m.colors.empty();
        tangents |= !m.tangents.empty();
        uvs |= keep_uvs && !m.uvs.empty();
    }
    auto append = [&](const MeshView& m, const glm::mat4& to_world, std::uint32_t offset,
                      bool transform) {
        const auto first = static_cast<std::uint32_t>(out->positions.size());
        const glm::mat3 a(to_world);
        const glm::mat3 n_matrix = glm::transpose(glm::mat3(glm::inverse(glm::dmat3(a))));
        for (const glm::vec3& p : m.positions)
            out->positions.push_back(transform ? glm::vec3(to_world * glm::vec4(p, 1.0f)) : p);
        if (normals) {
            if (m.normals.empty())
                out->normals.resize(out->positions.size(), glm::vec3(0.0f));
            else
                for (const glm::vec3& n : m.normals)
                    out->normals.push_back(transform ? n_matrix * n : n);
        }
        if (uvs) {
            if (m.uvs.empty())
                out->uvs.resize(out->positions.size(), glm::vec2(0.0f));
            else
                out->uvs.insert(out->uvs.end(), m.uvs.begin(), m.uvs.end());
        }
        if (colors) {  // a mesh without colours is white: its materials' colours unchanged
            if (m.colors.empty())
                out->colors.resize(out->positions.size(), glm::vec3(1.0f));
            else
                out->colors.insert(out->colors.end(), m.colors.begin(), m.colors.end());
        }
        // Tangents turn with the surface (A t); a mirror reverses the bitangent's side of the
        // tangent, so its sign flips (as Cycles does for negatively scaled objects).
        if (tangents) {
            if (m.tangents.empty())
                out->tangents.resize(out->positions.size(), glm::vec4(1, 0, 0, 1));
            const float flip = transform && glm::determinant(a) < 0.0f ? -1.0f : 1.0f;
            for (const glm::vec4& t : m.tangents)
                out->tangents.push_back(transform ? glm::vec4(a * glm::vec3(t), flip * t.w) : t);
        }
        // A mirror reverses the winding; swapping two corners keeps each triangle's front
        // side where it was, as Blender does with negatively scaled objects.
        const bool mirrored = transform && glm::determinant(a) < 0.0f;
        for (std::size_t t = 0; t < m.triangles.size(); ++t) {
            const glm::uvec3 tri = m.triangles[t] + first;
            out->triangles.push_back(mirrored ? glm::uvec3(tri.x, tri.z, tri.y) : tri);
            out->material_ids.push_back((m.material_ids.empty() ? 0 : m.material_ids[t]) + offset);
        }
    };
    append(world, glm::mat4(1.0f), 0, false);
    if (first_triangle) first_triangle->assign(scene.instances.size(), -1);
    for (std::size_t i = 0; i < scene.instances.size(); ++i) {
        if (only && !(*only)[i]) continue;
        if (first_triangle) (*first_triangle)[i] = std::int64_t(out->triangles.size());
        const Instance& inst = scene.instances[i];
        append(scene.instance_meshes[inst.mesh], inst.to_world, inst.material_offset, true);
    }
    return out;
}

void instanced_scene_bounds(const MeshView& world, const Scene& scene, glm::vec3& lo,
                            glm::vec3& hi) {
    auto vertex_box = [](const MeshView& m, glm::dvec3& l, glm::dvec3& h) {
        for (const glm::uvec3& t : m.triangles)
            for (int k = 0; k < 3; ++k) {
                const glm::dvec3 p(m.positions[t[k]]);
                l = glm::min(l, p);
                h = glm::max(h, p);
            }
    };
    const double inf = std::numeric_limits<double>::infinity();
    glm::dvec3 l(inf), h(-inf);
    vertex_box(world, l, h);
    std::vector<glm::dvec3> mesh_lo(scene.instance_meshes.size(), glm::dvec3(inf)),
        mesh_hi(scene.instance_meshes.size(), glm::dvec3(-inf));
    for (std::size_t m = 0; m < mesh_lo.size(); ++m)
        vertex_box(scene.instance_meshes[m], mesh_lo[m], mesh_hi[m]);
    for (const Instance& inst : scene.instances) {
        const glm::dvec3 a = mesh_lo[inst.mesh], b = mesh_hi[inst.mesh];
        if (!(a.x <= b.x)) continue;  // no triangles
        const glm::dmat4 m(inst.to_world);
        for (int corner = 0; corner < 8; ++corner) {
            const glm::dvec3 p((corner & 1) ? b.x : a.x, (corner & 2) ? b.y : a.y,
                               (corner & 4) ? b.z : a.z);
            const glm::dvec3 w(m * glm::dvec4(p, 1.0));
            l = glm::min(l, w);
            h = glm::max(h, w);
        }
    }
    for (int k = 0; k < 3; ++k) {
        lo[k] = std::nextafter(static_cast<float>(l[k]), -INFINITY);
        hi[k] = std::nextafter(static_cast<float>(h[k]), INFINITY);
    }
}

}  // namespace glslppm
