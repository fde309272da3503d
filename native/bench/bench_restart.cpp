// glslppm-bench restart: the rendered viewport's restart times to the first new image (one
// pass run and the film read back), against building a new renderer:
//   camera   Renderer::set_camera (a camera move: film and camera reset, no MTBVH build)
//   tables   Renderer::update_tables (a material colour edit: tables re-uploaded)
//   rebuild  a new Renderer (MTBVH build, GL set-up, programs from the process's binaries)
// Each restart is timed `--moves` times; the median and the largest are reported, with the
// same pass and film read without a restart beside them (the restart's own cost is the
// difference).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "bench/bench_scene.h"
#include "render/renderer.h"

using namespace glslppm;

namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

struct Timings {
    std::vector<double> seconds;
    double median() const {
        std::vector<double> s = seconds;
        std::sort(s.begin(), s.end());
        return s.empty() ? 0.0 : s[s.size() / 2];
    }
    double largest() const {
        return seconds.empty() ? 0.0 : *std::max_element(seconds.begin(), seconds.end());
    }
};

// The k-th viewport move: the camera turned by k half-degrees about its own up axis and
// moved sideways by a thousandth of its distance from the origin per step.
Camera moved(const Camera& camera, int k) {
    Camera c = camera;
    const glm::mat4 turn = glm::rotate(glm::mat4(1.0f), glm::radians(0.5f * float(k)),
                                       glm::vec3(0, 1, 0));
    c.to_world = camera.to_world * turn;
    const float step = 1e-3f * glm::length(glm::vec3(camera.to_world[3])) * float(k);
    c.to_world[3] += camera.to_world[0] * step;
    return c;
}

}  // namespace

int bench_restart(int argc, char** argv) {
    RenderSettings settings;
    settings.width = 1920;
    settings.height = 1080;
    settings.photons_per_pass = 65536;
    int moves = 10;
    bool json = false;
    std::string scene_spec = "million";
    for (int i = 0; i < argc; ++i) {
        const std::string a = argv[i];
        if (parse_render_option(argc, argv, i, settings, scene_spec)) continue;
        if (a == "--moves") moves = static_cast<int>(option_integer(a, argc, argv, i));
        else if (a == "--json") json = true;
        else {
            std::fprintf(stderr, "glslppm-bench restart: unknown option %s\n", a.c_str());
            return 2;
        }
    }
    if (moves < 1) {
        std::fprintf(stderr, "glslppm-bench restart: --moves must be at least 1\n");
        return 2;
    }
    try {
        const Scene scene = make_bench_scene(scene_spec, float(settings.width) / settings.height);
        Timings rebuild, camera, tables, steady;
        RenderStats stats;
        // The first renderer compiles the programs; later ones load their binaries, as a
        // viewport rebuild in a running Blender does.
        Renderer(scene, settings).run(1);
        for (int k = 0; k < std::max(1, moves / 4); ++k) {
            const auto start = Clock::now();
            Renderer fresh(scene, settings);
            fresh.run(1);
            fresh.film();
            rebuild.seconds.push_back(since(start));
        }
        Renderer renderer(scene, settings);
        renderer.run(4);
        renderer.film();
        for (int k = 1; k <= moves; ++k) {
            const auto start = Clock::now();
            if (!renderer.set_camera(moved(scene.camera, k)))
                throw std::runtime_error("set_camera refused a camera of the same kind");
            renderer.run(1);
            renderer.film();
            camera.seconds.push_back(since(start));
            renderer.run(2);  // the viewport refines between moves
            // The same pass and film read without a restart: what the restart adds is the
            // difference.
            const auto pass_start = Clock::now();
            renderer.run(1);
            renderer.film();
            steady.seconds.push_back(since(pass_start));
        }
        Scene edited = scene;
        for (int k = 1; k <= moves; ++k) {
            edited.materials[0].color = glm::vec3(0.2f + 0.05f * float(k % 10), 0.5f, 0.5f);
            const auto start = Clock::now();
            if (!renderer.update_tables(edited))
                throw std::runtime_error("update_tables refused a colour edit");
            renderer.run(1);
            renderer.film();
            tables.seconds.push_back(since(start));
            renderer.run(3);
        }
        stats = renderer.stats();
        if (json) {
            const nlohmann::json out = {
                {"bench", "restart"},
                {"scene", scene_spec},
                {"triangles", stats.triangles},
                {"width", settings.width},
                {"height", settings.height},
                {"photons_per_pass", settings.photons_per_pass},
                {"moves", moves},
                {"renderer", stats.renderer},
                {"camera_restart_seconds_median", camera.median()},
                {"camera_restart_seconds_max", camera.largest()},
                {"table_update_seconds_median", tables.median()},
                {"table_update_seconds_max", tables.largest()},
                {"pass_and_film_seconds_median", steady.median()},
                {"rebuild_seconds_median", rebuild.median()},
                {"rebuild_seconds_max", rebuild.largest()},
                {"camera_updates", stats.camera_updates},
                {"table_updates", stats.table_updates},
            };
            std::printf("%s\n", out.dump().c_str());
        } else {
            std::printf("scene %s (%zu triangles), %dx%d, %u photons/pass, on %s\n",
                        scene_spec.c_str(), stats.triangles, settings.width, settings.height,
                        settings.photons_per_pass, stats.renderer.c_str());
            std::printf("  time to the first new image (one pass + film), median / largest of %d:\n",
                        moves);
            std::printf("  camera move   %8.1f / %8.1f ms\n", 1e3 * camera.median(),
                        1e3 * camera.largest());
            std::printf("  table update  %8.1f / %8.1f ms\n", 1e3 * tables.median(),
                        1e3 * tables.largest());
            std::printf("  new renderer  %8.1f / %8.1f ms\n", 1e3 * rebuild.median(),
                        1e3 * rebuild.largest());
            std::printf("  (one pass + film without a restart: %.1f ms)\n",
                        1e3 * steady.median());
        }
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "glslppm-bench restart: %s\n", e.what());
        return 1;
    }
}
