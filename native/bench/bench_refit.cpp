// glslppm-bench refit [--triangles N] [--amplitudes a,b,...] [--rays R] [--json]
//
// Issue 32's question for deforming meshes: per pass, refit the frame's tree, rebuild it, or
// keep a motion-aware tree (a box per motion step per node, interpolated in traversal)?
// All three give the same image (every one bounds the triangles at the pass's time), so they
// differ only in what a pass costs: the tree's upkeep and the traversal's work.
//
// A bumpy sphere of N triangles ripples as the `+deform` bench scenes do (motion steps at
// t = -1, 0, +1; each vertex's z moves by amplitude x size x t x sin(12 (x + y) / size), so a
// vertex between steps is exactly the steps' lerp). For each amplitude, at t = 0.5 (between
// steps: the motion-aware tree's loosest) and t = 1 (on a step), it reports:
//   - rebuild: the time of a full build (SAH, threading, packing) of the mesh at t;
//   - refit: the time of one host refit of the frame's tree at t (the renderer refits on the
//     GPU instead: docs/motion_blur.md); its topology is the frame's;
//   - for each of the rebuilt, refitted and motion-aware trees, the nodes and triangles a ray
//     visits (CPU traversal counts, the same rays for all three), which is what a GPU pass
//     pays per ray; the motion-aware tree's boxes are the lerp of the refitted trees' boxes
//     at the bracketing steps, which is exactly what it would test (it also reads two boxes
//     per node and lerps them, which these counts do not charge it).
#include <bit>
#include <chrono>
#include <cstdio>
#include <random>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <nlohmann/json.hpp>

#include "bench/bench_scene.h"
#include "bvh/aabb.h"
#include "bvh/packed_bvh.h"
#include "bvh/traverse_cpu.h"
#include "procedural/bumpy_sphere_mesh.h"

namespace {

using namespace glslppm;
using Clock = std::chrono::steady_clock;

inline std::int32_t float_bits(float f) { return std::bit_cast<std::int32_t>(f); }

double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

// The mesh's vertices at time t (the steps' lerp, linear in t by construction).
std::vector<glm::vec3> rippled(const OwnedMesh& mesh, float amplitude, float t) {
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (const glm::vec3& p : mesh.positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
    const float size = glm::length(hi - lo), wave = 12.0f / size;
    std::vector<glm::vec3> out(mesh.positions);
    for (glm::vec3& p : out) p.z += amplitude * size * t * std::sin(wave * (p.x + p.y));
    return out;
}

// The frame's tree with its triangles at `positions` and its boxes refitted: leaves padded
// as the build pads them, inner boxes the unions of their children's (one backwards sweep:
// in preorder every descendant comes after its ancestor).
void refit(const OwnedMesh& mesh, const std::vector<glm::vec3>& positions,
           const std::vector<std::int32_t>& parent, PackedBvh& bvh) {
    for (std::uint32_t i = 0; i < bvh.triangle_count; ++i) {
        const auto id = static_cast<std::size_t>(float_bits(bvh.triangles[3 * i + 1].w));
        const glm::uvec3 v = mesh.triangles[id];
        for (int c = 0; c < 3; ++c)
            bvh.triangles[3 * i + c] = glm::vec4(positions[v[c]], bvh.triangles[3 * i + c].w);
    }
    std::vector<Aabb> box(bvh.node_count);
    for (std::int64_t j = std::int64_t(bvh.node_count) - 1; j >= 0; --j) {
        const std::int32_t count = float_bits(bvh.nodes[2 * j + 1].w);
        if (count > 0) {
            const std::int32_t first = float_bits(bvh.nodes[2 * j].w);
            Aabb leaf;
            for (std::int32_t i = first; i < first + count; ++i)
                for (int c = 0; c < 3; ++c) leaf.grow(glm::vec3(bvh.triangles[3 * i + c]));
            box[j] = pad_box(leaf);
        }
        bvh.nodes[2 * j] = glm::vec4(box[j].lo, bvh.nodes[2 * j].w);
        bvh.nodes[2 * j + 1] = glm::vec4(box[j].hi, bvh.nodes[2 * j + 1].w);
        if (parent[j] >= 0) box[parent[j]].grow(box[j]);
    }
}

// The motion-aware tree at u between two steps' refitted trees: boxes lerped, triangles at
// the time itself (they are what the tree bounds).
PackedBvh lerped_boxes(const PackedBvh& a, const PackedBvh& b, const PackedBvh& at, float u) {
    PackedBvh out = at;
    for (std::size_t k = 0; k < out.nodes.size(); ++k)
        out.nodes[k] = glm::vec4(glm::mix(glm::vec3(a.nodes[k]), glm::vec3(b.nodes[k]), u),
                                 out.nodes[k].w);
    return out;
}

// Rays from outside the mesh's box towards random points inside it (as bench bvh's).
TraversalCounts trace(const PackedBvh& bvh, std::size_t rays) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
    auto in_ball = [&] {
        glm::vec3 p;
        do p = glm::vec3(uni(rng), uni(rng), uni(rng));
        while (glm::dot(p, p) > 1.0f || glm::dot(p, p) < 1e-4f);
        return p;
    };
    TraversalCounts counts;
    for (std::size_t i = 0; i < rays; ++i) {
        const glm::vec3 origin = glm::normalize(in_ball()) * (2.0f + 0.5f * (1.0f + uni(rng)));
        const glm::vec3 target = in_ball();
        closest_hit(bvh, Ray{origin, glm::normalize(target - origin), 0.0f, 1e30f}, &counts);
    }
    return counts;
}

struct Row {
    float amplitude = 0, t = 0;
    double rebuild_ms = 0, refit_ms = 0;
    double nodes[3] = {}, triangles[3] = {};  // rebuilt, refitted, motion-aware
};

int usage() {
    std::fprintf(stderr, "usage: glslppm-bench refit [--triangles N] [--amplitudes a,b,...] "
                         "[--rays R] [--json]\n");
    return 2;
}

}  // namespace

int bench_refit(int argc, char** argv) {
    std::size_t triangles = 1000000, rays = 200000;
    std::vector<float> amplitudes{0.02f, 0.1f, 0.3f};
    bool json = false;
    for (int i = 0; i < argc; ++i) {
        const std::string_view arg = argv[i];
        const bool has_value = i + 1 < argc;
        if (arg == "--triangles" && has_value) {
            triangles = static_cast<std::size_t>(option_integer(std::string(arg), argc, argv, i));
        } else if (arg == "--rays" && has_value) {
            rays = static_cast<std::size_t>(option_integer(std::string(arg), argc, argv, i));
        } else if (arg == "--amplitudes" && has_value) {
            amplitudes.clear();
            std::stringstream list(argv[++i]);
            for (std::string item; std::getline(list, item, ',');) amplitudes.push_back(std::stof(item));
        } else if (arg == "--json") {
            json = true;
        } else {
            return usage();
        }
    }
    OwnedMesh mesh = make_sphere_mesh(triangles);
    const PackedBvh frame = build_packed_bvh(validate_mesh(mesh.view(), 1), {}, 6);
    const std::vector<std::int32_t> parent = node_parents(frame);
    std::vector<Row> rows;
    for (const float amplitude : amplitudes) {
        PackedBvh step0 = frame, step1 = frame;
        refit(mesh, rippled(mesh, amplitude, 0.0f), parent, step0);
        refit(mesh, rippled(mesh, amplitude, 1.0f), parent, step1);
        for (const float t : {0.5f, 1.0f}) {
            Row row{amplitude, t};
            OwnedMesh moved = mesh;
            moved.positions = rippled(mesh, amplitude, t);
            auto start = Clock::now();
            const PackedBvh rebuilt = build_packed_bvh(validate_mesh(moved.view(), 1), {}, 6);
            row.rebuild_ms = 1e3 * seconds_since(start);
            PackedBvh refitted = frame;
            start = Clock::now();
            refit(mesh, moved.positions, parent, refitted);
            row.refit_ms = 1e3 * seconds_since(start);
            const PackedBvh aware = lerped_boxes(step0, step1, refitted, t);
            const PackedBvh* trees[3] = {&rebuilt, &refitted, &aware};
            for (int k = 0; k < 3; ++k) {
                const TraversalCounts c = trace(*trees[k], rays);
                row.nodes[k] = double(c.nodes_visited) / double(rays);
                row.triangles[k] = double(c.triangles_tested) / double(rays);
            }
            rows.push_back(row);
        }
    }
    if (json) {
        for (const Row& r : rows) {
            const nlohmann::json out = {
                {"bench", "refit"}, {"triangles", frame.triangle_count}, {"rays", rays},
                {"amplitude", r.amplitude}, {"t", r.t}, {"rebuild_ms", r.rebuild_ms},
                {"host_refit_ms", r.refit_ms},
                {"nodes_per_ray", {{"rebuilt", r.nodes[0]}, {"refitted", r.nodes[1]},
                                   {"motion_aware", r.nodes[2]}}},
                {"triangles_per_ray", {{"rebuilt", r.triangles[0]}, {"refitted", r.triangles[1]},
                                       {"motion_aware", r.triangles[2]}}}};
            std::printf("%s\n", out.dump().c_str());
        }
        return 0;
    }
    std::printf("refit / rebuild / motion-aware tree: bumpy sphere, %u triangles, %zu rays\n",
                frame.triangle_count, rays);
    std::printf("%9s %4s %11s %9s   %27s   %27s\n", "amplitude", "t", "rebuild ms", "refit ms",
                "nodes/ray rebuilt refit aware", "tris/ray rebuilt refit aware");
    for (const Row& r : rows)
        std::printf("%9.3f %4.1f %11.1f %9.1f   %9.1f %8.1f %8.1f   %9.1f %8.1f %8.1f\n",
                    r.amplitude, r.t, r.rebuild_ms, r.refit_ms, r.nodes[0], r.nodes[1], r.nodes[2],
                    r.triangles[0], r.triangles[1], r.triangles[2]);
    return 0;
}
