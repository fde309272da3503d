// glslppm-bench bvh --triangles N [--leaf-size K] [--order-count 6|1] [--rays R] [--json]
// Builds a procedural bumpy sphere of N triangles, then times BVH build + threading +
// packing and reports the storage of the MTBVH and the TBVH (Hachisuka 2015 counts about
// 14 and 9 vec4 per triangle). With --rays, also traces R random rays on the CPU through
// both and reports the mean nodes and triangles visited per ray.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <string_view>

#include "bvh/packed_bvh.h"
#include <nlohmann/json.hpp>

#include "bench/bench_scene.h"
#include "procedural/bumpy_sphere_mesh.h"
#include "bvh/traverse_cpu.h"

namespace {

using namespace glslppm;

struct RayStats {
    double seconds = 0.0;
    double nodes_per_ray = 0.0, triangles_per_ray = 0.0, hit_fraction = 0.0;
};

// Rays from a shell of radius 2..3 around the unit sphere towards random points inside it.
RayStats trace_rays(const PackedBvh& bvh, std::size_t rays) {
    RayStats stats;
    if (rays == 0) return stats;
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> uni(-1.0f, 1.0f);
    auto random_point = [&](float radius) {
        glm::vec3 p;
        do p = glm::vec3(uni(rng), uni(rng), uni(rng));
        while (glm::dot(p, p) > 1.0f || glm::dot(p, p) < 1e-4f);
        return p * radius;
    };
    TraversalCounts counts;
    std::size_t hits = 0;
    const auto start = std::chrono::steady_clock::now();
    for (std::size_t i = 0; i < rays; ++i) {
        const glm::vec3 origin =
            glm::normalize(random_point(1.0f)) * (2.0f + 0.5f * (1.0f + uni(rng)));
        const glm::vec3 target = random_point(1.0f);
        const Ray ray{origin, glm::normalize(target - origin), 0.0f, 1e30f};
        hits += closest_hit(bvh, ray, &counts).triangle >= 0 ? 1 : 0;
    }
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    stats.nodes_per_ray = static_cast<double>(counts.nodes_visited) / rays;
    stats.triangles_per_ray = static_cast<double>(counts.triangles_tested) / rays;
    stats.hit_fraction = static_cast<double>(hits) / rays;
    return stats;
}

int usage() {
    std::fprintf(stderr,
                 "usage: glslppm-bench bvh --triangles N [--leaf-size K] [--bins B]\n"
                 "                         [--order-count 6|1] [--rays R] [--serial] [--json]\n");
    return 2;
}

}  // namespace

int bench_bvh(int argc, char** argv) {
    std::size_t triangles = 100000, rays = 0;
    int order_count = 6;
    bool json = false;
    BvhBuildOptions options;
    for (int i = 0; i < argc; ++i) {
        const std::string_view arg = argv[i];
        const bool has_value = i + 1 < argc;
        if (arg == "--triangles" && has_value)
            triangles = static_cast<std::size_t>(option_integer(std::string(arg), argc, argv, i));
        else if (arg == "--leaf-size" && has_value)
            options.leaf_size = static_cast<int>(option_integer(std::string(arg), argc, argv, i));
        else if (arg == "--bins" && has_value)
            options.bins = static_cast<int>(option_integer(std::string(arg), argc, argv, i));
        else if (arg == "--order-count" && has_value)
            order_count = static_cast<int>(option_integer(std::string(arg), argc, argv, i));
        else if (arg == "--rays" && has_value)
            rays = static_cast<std::size_t>(option_integer(std::string(arg), argc, argv, i));
        else if (arg == "--serial")
            options.parallel = false;
        else if (arg == "--json")
            json = true;
        else
            return usage();
    }
    if (order_count != 6 && order_count != 1) return usage();

    const OwnedMesh mesh = make_sphere_mesh(triangles);
    ValidMesh valid;
    PackedBvh packed, other;
    try {
        valid = validate_mesh(mesh.view(), 1);
        packed = build_packed_bvh(valid, options, order_count);
        // The other layout, for its storage figure (and the ray comparison).
        other = build_packed_bvh(valid, options, order_count == 6 ? 1 : 6);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench bvh: %s\n", e.what());
        return 1;
    }
    const PackedBvh& mtbvh = order_count == 6 ? packed : other;
    const PackedBvh& tbvh = order_count == 6 ? other : packed;
    const RayStats mt_rays = trace_rays(mtbvh, rays);
    const RayStats t_rays = trace_rays(tbvh, rays);
    const BvhStats& s = packed.stats;

    if (json) {
        nlohmann::json out = {
            {"bench", "bvh"},
            {"triangles", s.triangles},
            {"degenerate_dropped", s.degenerate_dropped},
            {"leaf_size", options.leaf_size},
            {"bins", options.bins},
            {"parallel", options.parallel},
            {"order_count", order_count},
            {"build_seconds", s.total_seconds()},
            {"sah_build_seconds", s.build_seconds},
            {"thread_seconds", s.thread_seconds},
            {"pack_seconds", s.pack_seconds},
            {"nodes", s.nodes},
            {"leaves", s.leaves},
            {"max_depth", s.max_depth},
            {"bytes_total", s.bytes_total},
            {"bytes_per_triangle", s.bytes_per_triangle},
            {"mtbvh_bytes_per_triangle", mtbvh.stats.bytes_per_triangle},
            {"tbvh_bytes_per_triangle", tbvh.stats.bytes_per_triangle},
            {"mtbvh_vec4_per_triangle", mtbvh.stats.vec4_per_triangle()},
            {"tbvh_vec4_per_triangle", tbvh.stats.vec4_per_triangle()},
        };
        if (rays > 0) {
            out["rays"] = rays;
            out["mtbvh_nodes_per_ray"] = mt_rays.nodes_per_ray;
            out["tbvh_nodes_per_ray"] = t_rays.nodes_per_ray;
            out["mtbvh_triangles_per_ray"] = mt_rays.triangles_per_ray;
            out["tbvh_triangles_per_ray"] = t_rays.triangles_per_ray;
            out["mtbvh_cpu_mrays_per_second"] = rays / mt_rays.seconds * 1e-6;
            out["tbvh_cpu_mrays_per_second"] = rays / t_rays.seconds * 1e-6;
        }
        std::printf("%s\n", out.dump().c_str());
        return 0;
    }
    std::printf("BVH benchmark: bumpy sphere, %zu triangles (%zu degenerate dropped)\n",
                s.triangles, s.degenerate_dropped);
    std::printf("  leaf size %d, %d bins, %s, %s\n", options.leaf_size, options.bins,
                options.parallel ? "parallel" : "serial", order_count == 6 ? "MTBVH" : "TBVH");
    std::printf("  %-28s %10.4f s\n", "SAH build", s.build_seconds);
    std::printf("  %-28s %10.4f s\n", "threading", s.thread_seconds);
    std::printf("  %-28s %10.4f s\n", "packing", s.pack_seconds);
    std::printf("  %-28s %10.4f s\n", "total", s.total_seconds());
    std::printf("  %-28s %10zu\n", "nodes", s.nodes);
    std::printf("  %-28s %10zu\n", "leaves", s.leaves);
    std::printf("  %-28s %10d\n", "max depth", s.max_depth);
    std::printf("  %-28s %10.2f B  (%5.2f vec4)\n", "MTBVH bytes per triangle",
                mtbvh.stats.bytes_per_triangle, mtbvh.stats.vec4_per_triangle());
    std::printf("  %-28s %10.2f B  (%5.2f vec4)\n", "TBVH bytes per triangle",
                tbvh.stats.bytes_per_triangle, tbvh.stats.vec4_per_triangle());
    if (rays > 0) {
        std::printf("  %zu rays, CPU:        %12s %12s\n", rays, "MTBVH", "TBVH");
        std::printf("  %-28s %12.2f %12.2f\n", "nodes per ray", mt_rays.nodes_per_ray,
                    t_rays.nodes_per_ray);
        std::printf("  %-28s %12.2f %12.2f\n", "triangles per ray", mt_rays.triangles_per_ray,
                    t_rays.triangles_per_ray);
        std::printf("  %-28s %12.3f %12.3f\n", "Mrays/s", rays / mt_rays.seconds * 1e-6,
                    rays / t_rays.seconds * 1e-6);
    }
    return 0;
}
