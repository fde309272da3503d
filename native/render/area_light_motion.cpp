// Moving area lights (docs/motion_blur.md). An area light is emissive triangles of the
// placed-once mesh (render/area_lights.h): the leaves that hold them are grown once, at
// preparation, over the light's whole sweep (and the inner boxes with them), so that the
// tree holds the light at every time of the shutter without a refit; per pass the light's
// packed triangles, their normals and their emitter records are rewritten at the pass's
// time. Scenes without a moving area light never come here.
#include <algorithm>
#include <bit>

#include "bvh/aabb.h"
#include "render/area_lights.h"
#include "render/emitters.h"
#include "render/gpu_layout.h"
#include "render/pipeline.h"

namespace glslppm {
namespace {

inline std::int32_t float_bits(float f) { return std::bit_cast<std::int32_t>(f); }

// Every place the light's corners take in the shutter: 64 samples per step interval, padded
// by 1e-3 of the box for the slerp's chord error (as grow_bounds_over_motion pads).
Aabb sweep_box(const MovingLight& l) {
    Aabb box;
    Light probe = l.frame;
    const std::vector<double>& times = l.motion.times;
    const std::size_t intervals = std::max<std::size_t>(times.size() - 1, 1);
    for (std::size_t s = 0; s < intervals; ++s)
        for (int j = 0; j <= 64; ++j) {
            const double u = j / 64.0;
            const double t =
                times.size() == 1 ? times[0] : times[s] * (1.0 - u) + times[s + 1] * u;
            probe.to_world = l.motion.at(t);
            for (const glm::vec3& p : area_light_corners(probe)) box.grow(p);
        }
    const glm::vec3 pad(1e-3f * glm::length(box.extent()));
    return pad_box(Aabb{box.lo - pad, box.hi + pad});
}

// A moving emitting instance's triangle over the shutter, sampled and padded as a light's.
Aabb emitter_sweep_box(const MovingMeshEmitter& e, std::size_t triangle) {
    Aabb box;
    const std::vector<double>& times = e.motion.times;
    const std::size_t intervals = std::max<std::size_t>(times.size() - 1, 1);
    const glm::uvec3 corners = e.triangles[triangle];
    for (std::size_t s = 0; s < intervals; ++s)
        for (int j = 0; j <= 64; ++j) {
            const double u = j / 64.0;
            const double t =
                times.size() == 1 ? times[0] : times[s] * (1.0 - u) + times[s + 1] * u;
            const glm::mat4 m = e.motion.at(t);
            for (int c = 0; c < 3; ++c)
                box.grow(glm::vec3(m * glm::vec4(e.positions[corners[c]], 1.0f)));
        }
    const glm::vec3 pad(1e-3f * glm::length(box.extent()));
    return pad_box(Aabb{box.lo - pad, box.hi + pad});
}

}  // namespace

void locate_area_lights(const Scene& scene, std::vector<MovingLight>& lights) {
    // with_area_lights appends their triangles after the scene's, light by light.
    std::vector<std::int64_t> first(scene.lights.size(), -1);
    auto next = static_cast<std::int64_t>(scene.mesh.triangles.size());
    for (std::size_t i = 0; i < scene.lights.size(); ++i) {
        if (scene.lights[i].kind != LightKind::Area) continue;
        first[i] = next;
        next += static_cast<std::int64_t>(area_light_corners(scene.lights[i]).size()) - 2;
    }
    for (MovingLight& l : lights) {
        if (l.frame.kind != LightKind::Area) continue;
        l.first_triangle = first[l.light];
        l.end_triangle = l.first_triangle + std::int64_t(area_light_corners(l.frame).size()) - 2;
    }
}

void grow_over_area_light_motion(const MotionPlan& plan, PackedBvh& bvh) {
    struct Sweep {
        std::int64_t first, end;
        Aabb box;
    };
    std::vector<Sweep> sweeps;
    for (const MovingLight& l : plan.lights)
        if (l.frame.kind == LightKind::Area)
            sweeps.push_back({l.first_triangle, l.end_triangle, sweep_box(l)});
    if (sweeps.empty() && plan.mesh_emitters.empty()) return;
    const std::vector<std::int32_t> parent = node_parents(bvh);
    for (std::uint32_t j = 0; j < bvh.node_count; ++j) {
        const std::int32_t count = float_bits(bvh.nodes[2 * j + 1].w);
        if (count == 0) continue;
        Aabb box{glm::vec3(bvh.nodes[2 * j]), glm::vec3(bvh.nodes[2 * j + 1])};
        bool grown = false;
        const std::int32_t begin = float_bits(bvh.nodes[2 * j].w);
        for (std::int32_t i = begin; i < begin + count; ++i) {
            const std::int64_t id = float_bits(bvh.triangles[3 * std::size_t(i) + 1].w);
            for (const Sweep& s : sweeps)
                if (id >= s.first && id < s.end) {
                    box.grow(s.box);
                    grown = true;
                }
            for (const MovingMeshEmitter& e : plan.mesh_emitters)
                if (id >= e.first_triangle && id < e.end_triangle) {
                    box.grow(emitter_sweep_box(e, std::size_t(id - e.first_triangle)));
                    grown = true;
                }
        }
        if (!grown) continue;
        // The leaf and every node above it hold the sweep.
        for (std::int32_t n = std::int32_t(j); n >= 0; n = parent[std::size_t(n)]) {
            glm::vec4& lo = bvh.nodes[2 * std::size_t(n)];
            glm::vec4& hi = bvh.nodes[2 * std::size_t(n) + 1];
            lo = glm::vec4(glm::min(glm::vec3(lo), box.lo), lo.w);
            hi = glm::vec4(glm::max(glm::vec3(hi), box.hi), hi.w);
        }
    }
}

void Renderer::Gpu::move_area_lights(double t) {
    const MotionPlan& plan = *scene.motion;
    const EmitterTable& table = scene.emitters;
    const std::vector<glm::vec4>& triangles = two_level ? two_level->triangles : bvh->triangles;
    const std::vector<glm::vec4>& normals = two_level ? two_level->normals : bvh->normals;
    MotionScratch& s = motion;
    if (!s.area_lights_traced) {
        // Each moving area light's packed triangles (mesh 0's come first in two levels).
        s.area_lights_traced = true;
        for (std::size_t k = 0; k < plan.lights.size(); ++k) {
            const MovingLight& l = plan.lights[k];
            if (l.frame.kind != LightKind::Area) continue;
            for (std::size_t i = 0; i < table.triangle_records.size(); ++i) {
                const std::int64_t id = float_bits(triangles[3 * i + 1].w);
                if (id >= l.first_triangle && id < l.end_triangle)
                    s.area_triangles.push_back({k, i, std::size_t(id - l.first_triangle)});
            }
        }
    }
    constexpr GLsizeiptr kVec4 = sizeof(glm::vec4);
    std::size_t light = plan.lights.size();
    std::vector<glm::vec3> p;
    glm::vec3 front(0.0f);
    for (const AreaLightTriangle& a : s.area_triangles) {
        if (a.light != light) {
            light = a.light;
            Light moved = plan.lights[light].frame;
            moved.to_world = plan.lights[light].motion.at(t);
            p = area_light_corners(moved);
            front = glm::normalize(glm::vec3(moved.to_world * glm::vec4(0, 0, -1, 0)));
        }
        // The fan (0, k + 1, k + 2), as with_area_lights makes it.
        const glm::vec3 v[3] = {p[0], p[a.local + 1], p[a.local + 2]};
        glm::vec4 out[3];
        for (int c = 0; c < 3; ++c) out[c] = glm::vec4(v[c], triangles[3 * a.packed + c].w);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers.triangles);
        glBufferSubData(GL_SHADER_STORAGE_BUFFER, GLintptr(3 * a.packed) * kVec4, 3 * kVec4, out);
        if (buffers.normals && !normals.empty()) {
            for (int c = 0; c < 3; ++c) out[c] = glm::vec4(front, normals[3 * a.packed + c].w);
            glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers.normals);
            glBufferSubData(GL_SHADER_STORAGE_BUFFER, GLintptr(3 * a.packed) * kVec4, 3 * kVec4,
                            out);
        }
        const std::int32_t r = table.triangle_records[a.packed];
        if (r < 0) continue;  // dark
        const std::size_t at = EMITTER_VEC4 * std::size_t(r);
        for (int c = 0; c < 3; ++c)
            out[c] = glm::vec4(v[c], table.records[at + std::size_t(c)].w);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers.emitter_records);
        glBufferSubData(GL_SHADER_STORAGE_BUFFER, GLintptr(at) * kVec4, 3 * kVec4, out);
    }
}

}  // namespace glslppm
