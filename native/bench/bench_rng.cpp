// glslppm-bench rng: speed of the two GPU generators of shaders/common/rng.glsl, and their
// streams read back for dieharder (scripts/dieharder.sh, docs/rng.md).
//
//   glslppm-bench rng --generator paper|pcg [--threads T] [--per-thread K] [--passes P]
//                     [--seed S] [--device I] [--out FILE|-] [--format u24|u16|u32] [--json]
//
// Speed: a kernel that sums each thread's K numbers (so the compiler cannot drop the work),
// timed with GL_TIME_ELAPSED queries; numbers/s = T*K / GPU time (best of 5 runs).
// Stream: P passes (0 = until the reader closes the pipe) of K numbers per thread, threads
// interleaved (number k of threads 0..T-1, then number k+1), as neighbouring pixels use them.
// The paper's states carry over between passes; PCG gets a new seed per pass, as a renderer
// sets u_rng_seed per pass. Formats, both little-endian:
//   u24  floor(x * 2^24), 3 bytes per number, packed: every bit a float in [0,1) can carry
//        (both generators give at most 24 bits), so a fair dieharder input;
//   u16  floor(x * 2^16), 2 bytes per number: the top 16 bits only, to see whether a
//        generator's trouble lies in its lowest bits;
//   u32  floor(x * 2^32), 4 bytes per number; the low 8 bits are always 0 for PCG and nearly
//        always for the paper's generator, so dieharder's bit-level tests fail both.
#include <epoxy/gl.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "gl/egl_context.h"
#include "gl/shader_program.h"
#include "render/gpu_layout.h"
#include "render/rng_seed.h"

int bench_rng(int argc, char** argv);

namespace {

using glslppm::gl::ComputeProgram;
using glslppm::gl::EglContext;

constexpr GLuint kStateBinding = BINDING_RNG_STATES;  // where rng.glsl keeps the states

struct Options {
    std::string generator = "pcg";
    std::uint32_t threads = 65536;
    std::uint32_t per_thread = 64;
    std::uint64_t passes = 1;
    std::uint64_t seed = 1;
    int device = -1;
    std::string out;
    std::string format = "u24";
    bool json = false;
};

int usage(const char* why) {
    std::fprintf(stderr,
                 "glslppm-bench rng: %s\n"
                 "usage: glslppm-bench rng --generator paper|pcg [--threads T] "
                 "[--per-thread K] [--passes P (0: until the pipe closes)] [--seed S] "
                 "[--device I] [--out FILE|-] [--format u24|u16|u32] [--json]\n",
                 why);
    return 2;
}

bool parse(int argc, char** argv, Options& o, std::string& error) {
    for (int i = 0; i < argc; ++i) {
        const std::string arg = argv[i];
        auto value = [&](const char* name) -> const char* {
            if (i + 1 >= argc) {
                error = std::string(name) + " needs a value";
                return nullptr;
            }
            return argv[++i];
        };
        const char* v = nullptr;
        if (arg == "--json") {
            o.json = true;
            continue;
        }
        if (arg != "--generator" && arg != "--threads" && arg != "--per-thread" &&
            arg != "--passes" && arg != "--seed" && arg != "--device" && arg != "--out" &&
            arg != "--format") {
            error = "unknown argument " + arg;
            return false;
        }
        if ((v = value(arg.c_str())) == nullptr) return false;
        if (arg == "--generator") o.generator = v;
        if (arg == "--threads") o.threads = static_cast<std::uint32_t>(std::stoul(v));
        if (arg == "--per-thread") o.per_thread = static_cast<std::uint32_t>(std::stoul(v));
        if (arg == "--passes") o.passes = std::stoull(v);
        if (arg == "--seed") o.seed = std::stoull(v);
        if (arg == "--device") o.device = std::stoi(v);
        if (arg == "--out") o.out = v;
        if (arg == "--format") o.format = v;
    }
    if (o.generator != "paper" && o.generator != "pcg") error = "--generator is paper or pcg";
    if (o.format != "u24" && o.format != "u16" && o.format != "u32") {
        error = "--format is u24, u16 or u32";
    }
    if (o.threads == 0 || o.per_thread == 0) error = "--threads and --per-thread must be > 0";
    if (o.threads > 65535u * 64u) error = "--threads is at most 4194240";
    return error.empty();
}

// A buffer bound to an SSBO binding point; `bytes` of `data` (or zeros).
GLuint make_buffer(GLuint binding, std::size_t bytes, const void* data) {
    GLuint buffer = 0;
    glGenBuffers(1, &buffer);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffer);
    glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(bytes), data, GL_DYNAMIC_COPY);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, buffer);
    return buffer;
}

void upload_paper_states(GLuint buffer, const Options& o) {
    const std::vector<glm::vec4> seeds = glslppm::paper_rng_seeds(o.threads, o.seed);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffer);
    glBufferSubData(GL_SHADER_STORAGE_BUFFER, 0,
                    static_cast<GLsizeiptr>(seeds.size() * sizeof(glm::vec4)), seeds.data());
}

void dispatch(const ComputeProgram& program, const Options& o, std::uint32_t pcg_seed) {
    program.use();
    glUniform1ui(program.uniform("u_threads"), o.threads);
    glUniform1ui(program.uniform("u_per_thread"), o.per_thread);
    glUniform1ui(program.uniform("u_rng_seed"), pcg_seed);  // -1 location for the paper: no-op
    glDispatchCompute((o.threads + 63u) / 64u, 1, 1);
}

struct Timing {
    double seconds = 0.0;  // best of 5 runs
    std::string clock;     // "GL_TIME_ELAPSED", "GL_TIMESTAMP" or "wall"
};

// Best of 5 timed runs of the summing kernel (one more warms up). GL_TIME_ELAPSED first;
// llvmpipe reports ~1 ns for compute dispatches there, so GL_TIMESTAMP pairs next, and
// wall-clock time around glFinish when neither measures anything.
Timing time_generation(const ComputeProgram& sum_program, const Options& o) {
    GLuint queries[3];
    glGenQueries(3, queries);
    double elapsed = 1e30, stamped = 1e30, wall = 1e30;
    for (int run = 0; run < 6; ++run) {
        glFinish();
        const auto start = std::chrono::steady_clock::now();
        glQueryCounter(queries[1], GL_TIMESTAMP);
        glBeginQuery(GL_TIME_ELAPSED, queries[0]);
        dispatch(sum_program, o, static_cast<std::uint32_t>(o.seed) + 0x80000000u + run);
        glEndQuery(GL_TIME_ELAPSED);
        glQueryCounter(queries[2], GL_TIMESTAMP);
        glFinish();
        const double w =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        GLuint64 ns = 0, t0 = 0, t1 = 0;
        glGetQueryObjectui64v(queries[0], GL_QUERY_RESULT, &ns);
        glGetQueryObjectui64v(queries[1], GL_QUERY_RESULT, &t0);
        glGetQueryObjectui64v(queries[2], GL_QUERY_RESULT, &t1);
        if (run == 0) continue;
        elapsed = std::min(elapsed, static_cast<double>(ns) * 1e-9);
        stamped = std::min(stamped, static_cast<double>(t1 - t0) * 1e-9);
        wall = std::min(wall, w);
    }
    glDeleteQueries(3, queries);
    // A timer that reads under a hundredth of the wall time measured nothing.
    if (elapsed > 0.01 * wall) return {elapsed, "GL_TIME_ELAPSED"};
    if (stamped > 0.01 * wall) return {stamped, "GL_TIMESTAMP"};
    return {wall, "wall"};
}

}  // namespace

int bench_rng(int argc, char** argv) {
    Options o;
    std::string error;
    try {
        if (!parse(argc, argv, o, error)) return usage(error.c_str());
    } catch (const std::exception&) {
        return usage("a number argument is not a number");
    }
    try {
        EglContext context(o.device);
        const std::string define = o.generator == "paper" ? "RNG_PAPER" : "RNG_PCG";
        const ComputeProgram stream_program("tests/rng_stream.comp", {{define, ""}});
        const ComputeProgram sum_program("tests/rng_stream.comp", {{define, ""}, {"RNG_STREAM_SUM", ""}});

        const std::size_t count = std::size_t{o.threads} * o.per_thread;
        // The stream needs T*K floats in one SSBO; the summing kernel only T.
        GLint64 max_block = 0;
        glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block);
        const bool stream_fits =
            count * sizeof(float) <= static_cast<std::size_t>(max_block) && count <= UINT32_MAX;
        if (!stream_fits && (!o.out.empty() || o.passes != 1)) {
            throw std::runtime_error("a stream of " + std::to_string(count) + " numbers needs " +
                                     std::to_string(count * 4) + " bytes, over the driver's " +
                                     std::to_string(max_block) +
                                     "-byte SSBO limit: lower --threads or --per-thread");
        }
        const GLuint values =
            make_buffer(0, (stream_fits ? count : std::size_t{o.threads}) * sizeof(float), nullptr);
        const GLuint states = make_buffer(kStateBinding, std::size_t{o.threads} * 16, nullptr);
        if (o.generator == "paper") upload_paper_states(states, o);

        const Timing timing = time_generation(sum_program, o);
        const double gpu_seconds = timing.seconds;
        const double numbers_per_second = static_cast<double>(count) / gpu_seconds;

        // The stream, from fresh seeds.
        if (o.generator == "paper") upload_paper_states(states, o);
        std::signal(SIGPIPE, SIG_IGN);  // a closed pipe (dieharder done) ends the stream
        std::FILE* out = nullptr;
        std::unique_ptr<std::FILE, int (*)(std::FILE*)> owned(nullptr, &std::fclose);
        if (o.out == "-") {
            out = stdout;
        } else if (!o.out.empty()) {
            owned.reset(std::fopen(o.out.c_str(), "wb"));
            out = owned.get();
            if (out == nullptr) {
                std::fprintf(stderr, "glslppm-bench rng: cannot write %s: %s\n", o.out.c_str(),
                             std::strerror(errno));
                return 1;
            }
        }
        const int bits = o.format == "u24" ? 24 : o.format == "u16" ? 16 : 32;
        std::vector<float> host(stream_fits ? count : 0);
        std::vector<unsigned char> bytes(host.size() * static_cast<std::size_t>(bits / 8));
        double sum = 0.0;
        std::uint64_t written = 0, ones = 0;
        const auto start = std::chrono::steady_clock::now();
        // Without --out a too-large stream is skipped: only the speed is asked for.
        const std::uint64_t passes = !stream_fits ? 0 : o.passes == 0 ? UINT64_MAX : o.passes;
        bool closed = false;
        for (std::uint64_t pass = 0; pass < passes && !closed; ++pass) {
            dispatch(stream_program, o, static_cast<std::uint32_t>(o.seed + pass));
            glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
            glBindBuffer(GL_SHADER_STORAGE_BUFFER, values);
            glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0,
                               static_cast<GLsizeiptr>(count * sizeof(float)), host.data());
            unsigned char* b = bytes.data();
            for (float x : host) {
                sum += x;
                if (x >= 1.0f) ++ones;  // rng_next never gives 1; counted to prove it
                // Exact: x has at most 24 significant bits, and x < 1.
                const auto v = static_cast<std::uint32_t>(std::ldexp(double(x), bits));
                for (int byte = 0; byte < bits / 8; ++byte) *b++ = (v >> (8 * byte)) & 0xFF;
            }
            written += count;
            if (out != nullptr && std::fwrite(bytes.data(), 1, bytes.size(), out) != bytes.size())
                closed = true;
        }
        if (out != nullptr && !closed) std::fflush(out);
        const double wall =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        glDeleteBuffers(1, &values);
        glDeleteBuffers(1, &states);

        std::FILE* report = o.out == "-" ? stderr : stdout;
        const auto& info = context.info();
        if (o.json) {
            // The output path is the user's: the JSON library escapes it.
            const nlohmann::json out = {
                {"generator", o.generator},
                {"renderer", info.renderer},
                {"threads", o.threads},
                {"per_thread", o.per_thread},
                {"numbers_timed", count},
                {"seconds", gpu_seconds},
                {"clock", timing.clock},
                {"numbers_per_second", numbers_per_second},
                {"stream_numbers", written},
                {"stream_mean", written ? sum / static_cast<double>(written) : 0.0},
                {"stream_ones", ones},
                {"stream_numbers_per_second_with_readback", static_cast<double>(written) / wall},
                {"format", o.format},
                {"out", o.out}};
            std::fprintf(report, "%s\n", out.dump().c_str());
        } else {
            std::fprintf(report, "%s on %s: %.4g numbers/s (%s, %zu numbers in %.4g ms)\n",
                         o.generator.c_str(), info.renderer.c_str(), numbers_per_second,
                         timing.clock.c_str(), count, gpu_seconds * 1e3);
        }
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "glslppm-bench rng: %s\n", e.what());
        return 1;
    }
}
