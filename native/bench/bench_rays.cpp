// glslppm-bench rays: GPU rays per second for primary, shadow and incoherent (one cosine-
// diffuse bounce) rays, MTBVH against TBVH (Hachisuka 2015 reports the MTBVH 2-3x faster on
// incoherent rays), for several BVH leaf sizes and scenes. The GPU time of each batch comes
// from GL timer queries; a sample of the traced rays is traced again on the CPU
// (traverse_cpu.h) and the agreement printed, so a broken kernel cannot pass unnoticed.
// An untimed dispatch compiled with BVH_COUNT_VISITS measures the nodes and triangles each
// ray visits on the GPU, and the sample's counts must equal the CPU's TraversalCounts: a
// wrong MTBVH order gives the right hits and shows only in this work (and the time).
#include <epoxy/gl.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "bench/bench_scene.h"
#include "bvh/build_sah_bvh.h"
#include "bvh/packed_bvh.h"
#include "bvh/thread_mtbvh.h"
#include "bvh/traverse_cpu.h"
#include "gl/egl_context.h"
#include "gl/shader_program.h"

using namespace glslppm;

namespace {

constexpr GLuint kLocalSize = 64;  // bench/bench_rays.comp's local_size_x
const char* const kModes[3] = {"primary", "shadow", "incoherent"};

struct RaysOptions {
    std::size_t rays = std::size_t(1) << 20;  // per batch
    int batches = 4;
    int repeat = 3;  // timings of the batches; the fastest is reported
    std::vector<std::string> scenes = {"cornell", "million:100k", "million:1M"};
    std::vector<int> leaves = {1, 2, 4, 8};
    std::vector<int> layouts = {6, 1};  // order counts: MTBVH, TBVH
    std::size_t checked = 2048;         // rays per mode traced again on the CPU
    int device = -1;
    bool json = false;
};

struct ModeResult {
    double gpu_seconds = 0.0, wall_seconds = 0.0;
    std::uint64_t rays = 0;  // traced (shadow and incoherent: from valid primary hits only)
    std::size_t checked = 0, agreed = 0;
    // The counted dispatch: its rays' GPU nodes and triangles summed, and its sample traced
    // on the CPU, where count_agreed rays had the same result and exactly the same counts.
    std::uint64_t counted_rays = 0, gpu_nodes = 0, gpu_triangles = 0, cpu_nodes = 0;
    std::size_t count_checked = 0, count_agreed = 0;
    double nodes_per_ray() const { return counted_rays ? double(gpu_nodes) / counted_rays : 0; }
    double triangles_per_ray() const {
        return counted_rays ? double(gpu_triangles) / counted_rays : 0;
    }
    double rays_per_second() const { return gpu_seconds > 0 ? double(rays) / gpu_seconds : 0; }
};

struct Row {
    std::string scene;
    std::size_t triangles = 0, nodes = 0;
    int order_count = 6, leaf_size = 4;
    double build_seconds = 0.0;
    ModeResult modes[3];
};

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::vector<std::string> split(const std::string& list) {
    std::vector<std::string> out;
    std::size_t start = 0;
    while (start <= list.size()) {
        const std::size_t end = std::min(list.find(',', start), list.size());
        if (end > start) out.push_back(list.substr(start, end - start));
        start = end + 1;
    }
    return out;
}

// Shadow-ray targets: the emissive triangles, and point-like lights as degenerate triangles.
std::vector<glm::vec4> light_triangles(const Scene& scene, const ValidMesh& mesh) {
    std::vector<glm::vec4> out;
    for (std::uint32_t t : mesh.kept) {
        const std::uint32_t m = mesh.view.material_ids.empty() ? 0 : mesh.view.material_ids[t];
        if (glm::length(scene.materials[m].emission) <= 0.0f) continue;
        for (int k = 0; k < 3; ++k)
            out.emplace_back(mesh.view.positions[mesh.view.triangles[t][k]], 0.0f);
    }
    for (const Light& l : scene.lights) {
        if (l.kind == LightKind::Sun) continue;
        const glm::vec3 p = l.kind == LightKind::Area ? glm::vec3(l.to_world[3]) : l.position;
        for (int k = 0; k < 3; ++k) out.emplace_back(p, 0.0f);
    }
    if (out.empty()) throw std::invalid_argument("shadow rays: the scene has no light to aim at");
    return out;
}

class RayBench {
  public:
    RayBench(const RaysOptions& options) : options_(options), context_(options.device) {
        glGenBuffers(9, buffers_);
        glGenQueries(2, queries_);
    }
    ~RayBench() {
        glDeleteBuffers(9, buffers_);
        glDeleteQueries(2, queries_);
    }
    const gl::ContextInfo& info() const { return context_.info(); }

    // Uploads one packed BVH and the scene's lights and measures the three ray kinds.
    void measure(const Scene& scene, const PackedBvh& bvh, const std::vector<glm::vec4>& lights,
                 Row& row) {
        upload(0, bvh.nodes.size() * 16, bvh.nodes.data());
        upload(1, bvh.links.size() * 8, bvh.links.data());
        upload(2, bvh.triangles.size() * 16, bvh.triangles.data());
        upload(3, lights.size() * 16, lights.data());
        upload(4, options_.rays * 32, nullptr);
        upload(5, options_.rays * 4, nullptr);
        upload(6, (options_.rays / stride() + 1) * 48, nullptr);
        const GLuint zero = 0;
        upload(7, 4, &zero);
        upload(8, options_.rays * 8, nullptr);
        for (int mode = 0; mode < 3; ++mode) {
            const gl::ComputeProgram& program = this->program(mode, bvh.order_count);
            set_uniforms(program, scene, bvh, lights);
            // Untimed: the primary pass that stores hits for the other modes, and the
            // recorded rays checked on the CPU (also the warm-up).
            dispatch(program, 1, mode == 0, stride());
            if (mode == 0) valid_hits_ = read_count();
            check(bvh, mode, row.modes[mode]);
            // The same rays again, counting (primary rays store no hits this time: the
            // other modes start from the first dispatch's).
            const gl::ComputeProgram& counted = this->program(mode, bvh.order_count, true);
            set_uniforms(counted, scene, bvh, lights);
            dispatch(counted, 1, false, stride());
            check_counts(bvh, mode, row.modes[mode]);
            time_batches(program, row.modes[mode]);
            row.modes[mode].rays =
                std::uint64_t(options_.batches) * (mode == 0 ? options_.rays : valid_hits_);
        }
    }

  private:
    // GPU timestamps around the batches (llvmpipe's GL_TIME_ELAPSED reads ~0), and the wall
    // time from glFinish to glFinish; the fastest of --repeat timings, since other work on
    // the machine only ever adds time.
    void time_batches(const gl::ComputeProgram& program, ModeResult& result) {
        for (int rep = 0; rep < options_.repeat; ++rep) {
            glFinish();
            const auto start = std::chrono::steady_clock::now();
            glQueryCounter(queries_[0], GL_TIMESTAMP);
            for (int b = 0; b < options_.batches; ++b)
                dispatch(program, static_cast<std::uint32_t>(b + 2), false, 0);
            glQueryCounter(queries_[1], GL_TIMESTAMP);
            glFinish();
            const double wall = seconds_since(start);
            GLuint64 t0 = 0, t1 = 0;
            glGetQueryObjectui64v(queries_[0], GL_QUERY_RESULT, &t0);
            glGetQueryObjectui64v(queries_[1], GL_QUERY_RESULT, &t1);
            const double gpu = 1e-9 * static_cast<double>(t1 - t0);
            if (rep == 0 || gpu < result.gpu_seconds) {
                result.gpu_seconds = gpu;
                result.wall_seconds = wall;
            }
        }
    }

    std::uint32_t stride() const {
        return static_cast<std::uint32_t>(
            std::max<std::size_t>(1, options_.rays / options_.checked));
    }

    const gl::ComputeProgram& program(int mode, int order_count, bool counted = false) {
        gl::Defines d = {{mode == 0   ? "MODE_PRIMARY"
                          : mode == 1 ? "MODE_SHADOW"
                                      : "MODE_INCOHERENT",
                          "1"}};
        if (order_count == 1) d.push_back({"GLSLPPM_TBVH", "1"});
        if (counted) d.push_back({"BVH_COUNT_VISITS", "1"});
        return context_.programs().get("bench/bench_rays.comp", d);
    }

    // Fails with the size and what to lower when the driver's storage-buffer limit is hit.
    void upload(GLuint binding, std::size_t bytes, const void* data) {
        GLint64 largest = 0;
        glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &largest);
        if (largest > 0 && bytes > static_cast<std::size_t>(largest))
            throw gl::GlError("rays: buffer " + std::to_string(binding) + " needs " +
                              std::to_string(bytes >> 20) + " MiB, more than this GPU allows (" +
                              std::to_string(largest >> 20) + " MiB): lower --rays or the scene");
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers_[binding]);
        glBufferData(GL_SHADER_STORAGE_BUFFER,
                     static_cast<GLsizeiptr>(std::max<std::size_t>(bytes, 16)), data,
                     GL_DYNAMIC_COPY);
        if (glGetError() == GL_OUT_OF_MEMORY)
            throw gl::GlError("rays: out of GPU memory for buffer " + std::to_string(binding));
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, buffers_[binding]);
    }

    void set_uniforms(const gl::ComputeProgram& p, const Scene& scene, const PackedBvh& bvh,
                      const std::vector<glm::vec4>& lights) {
        p.use();
        const auto width = static_cast<GLuint>(std::ceil(std::sqrt(double(options_.rays))));
        const auto height = static_cast<GLuint>((options_.rays + width - 1) / width);
        glUniform1ui(p.uniform("bvh_node_count"), bvh.node_count);
        glUniform1ui(p.uniform("u_count"), static_cast<GLuint>(options_.rays));
        glUniform1ui(p.uniform("u_film_width"), width);
        glUniform1ui(p.uniform("u_film_height"), height);
        glUniformMatrix4fv(p.uniform("u_camera_to_world"), 1, GL_FALSE,
                           &scene.camera.to_world[0][0]);
        glUniform1f(p.uniform("u_tan_half_fov"), std::tan(0.5f * scene.camera.fov_x));
        glUniform1ui(p.uniform("u_light_count"), static_cast<GLuint>(lights.size() / 3));
    }

    void dispatch(const gl::ComputeProgram& p, std::uint32_t seed, bool write_hits,
                  std::uint32_t record_stride) {
        p.use();
        glUniform1ui(p.uniform("u_seed"), seed);
        glUniform1ui(p.uniform("u_write_hits"), write_hits ? 1u : 0u);
        glUniform1ui(p.uniform("u_record_stride"), record_stride);
        const auto groups =
            static_cast<std::uint32_t>((options_.rays + kLocalSize - 1) / kLocalSize);
        if (groups <= 65535u)
            glDispatchCompute(std::max(groups, 1u), 1, 1);
        else
            glDispatchCompute(32768u, (groups + 32767u) / 32768u, 1);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    }

    std::uint64_t read_count() {
        GLuint count = 0;
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers_[7]);
        glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, 4, &count);
        return count;
    }

    // Traces the recorded rays on the CPU through the same packed BVH and counts the rays
    // whose result (original triangle id, or shadow yes/no) is the GPU's.
    void check(const PackedBvh& bvh, int mode, ModeResult& result) {
        const std::size_t n = (options_.rays - 1) / stride() + 1;
        std::vector<glm::vec4> rec(3 * n);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers_[6]);
        glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(rec.size() * 16),
                           rec.data());
        std::vector<int> gpu(options_.rays);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers_[5]);
        glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(gpu.size() * 4),
                           gpu.data());
        for (std::size_t k = 0; k < n; ++k) {
            if (gpu[k * stride()] == -2) continue;  // no primary hit to start from: not traced
            const Ray ray{glm::vec3(rec[3 * k]), glm::vec3(rec[3 * k + 1]), rec[3 * k].w,
                          rec[3 * k + 1].w};
            const int got = std::bit_cast<int>(rec[3 * k + 2].x);
            const int want =
                mode == 1 ? (any_hit(bvh, ray) ? 1 : 0) : closest_hit(bvh, ray).triangle;
            ++result.checked;
            result.agreed += got == want && got == gpu[k * stride()] ? 1 : 0;
        }
    }

    // After the counted dispatch: sums the GPU's per-ray counts over every traced ray, and
    // traces the recorded sample on the CPU with TraversalCounts, which must be the GPU's
    // exactly (same BVH, same floats, same visiting order).
    void check_counts(const PackedBvh& bvh, int mode, ModeResult& result) {
        std::vector<int> gpu(options_.rays);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers_[5]);
        glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(gpu.size() * 4),
                           gpu.data());
        std::vector<glm::uvec2> work(options_.rays);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers_[8]);
        glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(work.size() * 8),
                           work.data());
        for (std::size_t i = 0; i < gpu.size(); ++i) {
            if (gpu[i] == -2) continue;
            ++result.counted_rays;
            result.gpu_nodes += work[i].x;
            result.gpu_triangles += work[i].y;
        }
        const std::size_t n = (options_.rays - 1) / stride() + 1;
        std::vector<glm::vec4> rec(3 * n);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers_[6]);
        glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(rec.size() * 16),
                           rec.data());
        for (std::size_t k = 0; k < n; ++k) {
            if (gpu[k * stride()] == -2) continue;
            const Ray ray{glm::vec3(rec[3 * k]), glm::vec3(rec[3 * k + 1]), rec[3 * k].w,
                          rec[3 * k + 1].w};
            TraversalCounts counts;
            const int want = mode == 1 ? (any_hit(bvh, ray, &counts) ? 1 : 0)
                                       : closest_hit(bvh, ray, &counts).triangle;
            const int got = std::bit_cast<int>(rec[3 * k + 2].x);
            const auto nodes = std::bit_cast<std::uint32_t>(rec[3 * k + 2].y);
            const auto triangles = std::bit_cast<std::uint32_t>(rec[3 * k + 2].z);
            ++result.count_checked;
            result.cpu_nodes += counts.nodes_visited;
            result.count_agreed += got == want && nodes == counts.nodes_visited &&
                                           triangles == counts.triangles_tested &&
                                           work[k * stride()] == glm::uvec2(nodes, triangles)
                                       ? 1
                                       : 0;
        }
    }

    RaysOptions options_;
    gl::EglContext context_;
    GLuint buffers_[9] = {};
    GLuint queries_[2] = {};
    std::uint64_t valid_hits_ = 0;
};

void print_json(const RaysOptions& o, const std::string& renderer, const std::vector<Row>& rows) {
    using nlohmann::json;
    double worst = 1.0, worst_counts = 1.0;
    json results = json::array();
    for (const Row& row : rows) {
        json r = {{"scene", row.scene},         {"triangles", row.triangles},
                  {"nodes", row.nodes},         {"layout", row.order_count == 6 ? "mtbvh" : "tbvh"},
                  {"leaf_size", row.leaf_size}, {"build_seconds", row.build_seconds}};
        for (int m = 0; m < 3; ++m) {
            const ModeResult& x = row.modes[m];
            const double agreement = x.checked ? double(x.agreed) / double(x.checked) : 1.0;
            const double count_agreement =
                x.count_checked ? double(x.count_agreed) / double(x.count_checked) : 1.0;
            worst = std::min(worst, agreement);
            worst_counts = std::min(worst_counts, count_agreement);
            r[kModes[m]] = {
                {"rays", x.rays},
                {"gpu_seconds", x.gpu_seconds},
                {"wall_seconds", x.wall_seconds},
                {"rays_per_second", x.rays_per_second()},
                {"checked", x.checked},
                {"agreement", agreement},
                // Work per ray of the counted dispatch (all its rays, GPU counts), and the
                // CPU's count over the checked sample with the fraction that matched exactly.
                {"counted_rays", x.counted_rays},
                {"nodes_per_ray", x.nodes_per_ray()},
                {"triangles_per_ray", x.triangles_per_ray()},
                {"count_checked", x.count_checked},
                {"cpu_nodes_per_ray",
                 x.count_checked ? double(x.cpu_nodes) / double(x.count_checked) : 0.0},
                {"count_agreement", count_agreement}};
        }
        results.push_back(r);
    }
    const json out = {{"bench", "rays"},          {"renderer", renderer},
                      {"rays_per_batch", o.rays}, {"batches", o.batches},
                      {"repeat", o.repeat},       {"results", results},
                      {"agreement_min", worst},   {"count_agreement_min", worst_counts}};
    std::printf("%s\n", out.dump(1).c_str());
}

void print_table(const RaysOptions& o, const std::string& renderer, const std::vector<Row>& rows) {
    std::printf("%s: %zu rays per batch, %d batches, fastest of %d (GPU time, timer queries)\n",
                renderer.c_str(), o.rays, o.batches, o.repeat);
    std::printf("%-16s %10s %6s %5s %14s %14s %14s %10s %12s\n", "scene", "triangles", "layout",
                "leaf", "primary Mr/s", "shadow Mr/s", "incoher. Mr/s", "CPU agree",
                "incoh. nodes");
    for (const Row& row : rows) {
        std::size_t checked = 0, agreed = 0;
        for (const ModeResult& m : row.modes) checked += m.checked, agreed += m.agreed;
        for (const ModeResult& m : row.modes) checked += m.count_checked, agreed += m.count_agreed;
        std::printf("%-16s %10zu %6s %5d %14.2f %14.2f %14.2f %9.2f%% %12.2f\n", row.scene.c_str(),
                    row.triangles, row.order_count == 6 ? "MTBVH" : "TBVH", row.leaf_size,
                    row.modes[0].rays_per_second() * 1e-6, row.modes[1].rays_per_second() * 1e-6,
                    row.modes[2].rays_per_second() * 1e-6,
                    checked ? 100.0 * double(agreed) / double(checked) : 100.0,
                    row.modes[2].nodes_per_ray());
    }
}

int usage() {
    std::fprintf(
        stderr,
        "usage: glslppm-bench rays [--rays N] [--batches B] [--repeat R] [--scenes a,b,...]\n"
        "       [--leaf 1,2,4,8] [--layout mtbvh,tbvh] [--check N] [--device D] [--json]\n"
        "  scenes: cornell, caustic, million[:N] (N like 100k, 1M), or a .gltf file\n");
    return 2;
}

bool parse(int argc, char** argv, RaysOptions& o) {
    for (int i = 0; i < argc; ++i) {
        const std::string a = argv[i];
        const bool has = i + 1 < argc;
        if (a == "--json")
            o.json = true;
        else if (a == "--rays" && has)
            o.rays = parse_count(argv[++i]);
        else if (a == "--batches" && has)
            o.batches = static_cast<int>(option_integer(a, argc, argv, i));
        else if (a == "--repeat" && has)
            o.repeat = static_cast<int>(option_integer(a, argc, argv, i));
        else if ((a == "--scenes" || a == "--scene") && has)
            o.scenes = split(argv[++i]);
        else if (a == "--check" && has)
            o.checked = parse_count(argv[++i]);
        else if (a == "--device" && has)
            o.device = static_cast<int>(option_integer(a, argc, argv, i));
        else if (a == "--leaf" && has) {
            o.leaves.clear();
            for (const std::string& s : split(argv[++i])) o.leaves.push_back(static_cast<int>(parse_integer("--leaf", s)));
        } else if (a == "--layout" && has) {
            o.layouts.clear();
            for (const std::string& s : split(argv[++i])) {
                if (s != "mtbvh" && s != "tbvh") return false;
                o.layouts.push_back(s == "mtbvh" ? 6 : 1);
            }
        } else {
            return false;
        }
    }
    return o.batches >= 1 && o.repeat >= 1 && !o.scenes.empty() && !o.leaves.empty() &&
           !o.layouts.empty() && o.rays <= (std::size_t(1) << 26) &&
           std::all_of(o.leaves.begin(), o.leaves.end(), [](int l) { return l >= 1 && l <= 64; });
}

}  // namespace

int bench_rays(int argc, char** argv) {
    RaysOptions options;
    try {
        if (!parse(argc, argv, options)) return usage();
    } catch (const std::exception& e) {
        std::fprintf(stderr, "glslppm-bench rays: %s\n", e.what());
        return 2;
    }
    try {
        RayBench bench(options);
        std::vector<Row> rows;
        for (const std::string& spec : options.scenes) {
            const Scene scene = make_bench_scene(spec);
            const ValidMesh mesh =
                validate_mesh(scene.mesh, static_cast<std::uint32_t>(scene.materials.size()));
            const std::vector<glm::vec4> lights = light_triangles(scene, mesh);
            for (int leaf : options.leaves) {
                BvhBuildOptions build;
                build.leaf_size = leaf;
                const auto start = std::chrono::steady_clock::now();
                const Bvh bvh = build_sah_bvh(mesh, build);
                const double sah_seconds = seconds_since(start);
                for (int order_count : options.layouts) {
                    const auto pack_start = std::chrono::steady_clock::now();
                    const PackedBvh packed = pack_bvh(mesh, bvh, thread_bvh(bvh, order_count));
                    Row row{spec,
                            packed.stats.triangles,
                            packed.stats.nodes,
                            order_count,
                            leaf,
                            sah_seconds + seconds_since(pack_start),
                            {}};
                    bench.measure(scene, packed, lights, row);
                    rows.push_back(row);
                    if (!options.json)
                        std::fprintf(stderr, "  %s %s leaf %d done\n", spec.c_str(),
                                     order_count == 6 ? "MTBVH" : "TBVH", leaf);
                }
            }
        }
        if (options.json)
            print_json(options, bench.info().renderer, rows);
        else
            print_table(options, bench.info().renderer, rows);
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "glslppm-bench rays: %s\n", e.what());
        return 1;
    }
}
