// The GPU pipeline of one Renderer (native/render/renderer.h keeps it behind a pointer): the
// GL thread, the compiled stage programs and every buffer, and a pass as its named stages
// (run_pass: eye trace, photon trace, hash, gather, end of pass). Only the Renderer's own
// sources include this file (renderer.cpp, renderer_setup.cpp, renderer_readback.cpp).
#pragma once

#include <algorithm>
#include <bit>
#include <cstddef>
#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include "bvh/packed_bvh.h"
#include "gl/buffer_reader.h"
#include "gl/gl_thread.h"
#include "gl/object_counts.h"
#include "gl/shader_program.h"
#include "render/emitters.h"
#include "render/gpu_layout.h"
#include "render/instancing.h"
#include "render/pppm_schedule.h"
#include "render/renderer.h"
#include "render/texture_atlas.h"
#include "render/tiled_render.h"
#include "scene/cancel.h"

namespace glslppm {
namespace pipeline_detail {

constexpr GLuint kLocalSize = 64;

// One 32-bit hash of the seed, pass and stage for the PCG generator's per-dispatch seed.
inline std::uint32_t mix_seed(std::uint64_t seed, std::uint64_t pass, std::uint32_t stage) {
    std::uint64_t z = seed * 0x9E3779B97F4A7C15ull + pass * 0xBF58476D1CE4E5B9ull + stage;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return static_cast<std::uint32_t>(z ^ (z >> 31));
}

}  // namespace pipeline_detail

using pipeline_detail::kLocalSize;
using pipeline_detail::mix_seed;

struct Renderer::Gpu {
    std::unique_ptr<gl::GlThread> thread;
    RenderSettings settings;
    PackedBvh bvh;  // what is uploaded: the two-level MTBVH's arrays when it is the path
    std::vector<glm::vec4> instances;  // two-level instance records, else empty
    InstancePlan instancing;
    std::size_t instance_count = 0;
    EmitterTable emitters;
    SceneBounds bounds;
    FrameBlock frame{};
    gl::Defines defines;
    std::string variant;
    std::uint32_t pixels = 0, photon_threads = 0, hash_cells = 0;
    // PPPM: photon steps stored side by side before one hash and gather, and each step's
    // slot in the photon buffer (photon_threads rounded up to 16); SPPM: 1 and photon_threads.
    std::uint32_t steps_per_gather = 1, photon_slot = 0;
    std::uint64_t passes = 0;
    std::vector<std::uint64_t> pass_indices;  // PPPM: the indices this worker ran
    int device = -1;
    double seconds = 0.0;
    double submit_seconds = 0.0, wait_seconds = 0.0;  // host time within `seconds` (run_workers)
    std::atomic<bool> cancel{false};
    const CancelFlag* setup_cancel = nullptr;  // the constructor's, polled per buffer
    float initial_radius = 0.0f;
    std::size_t gpu_bytes = 0;
    std::size_t gpu_bytes_per_pixel = 0;  // the per-pixel buffers' bytes for one pixel
    double gpu_bytes_per_photon = 0.0;    // the per-photon buffers' bytes for one photon

    GLuint ubo = 0;
    GLuint queries[5] = {0, 0, 0, 0, 0};  // stage boundaries when profiling
    double stage_seconds[4] = {0, 0, 0, 0};
    std::vector<GLuint> buffers;  // every SSBO, deleted together
    gl::BufferReader reader;      // film, passes and photons read back
    GLuint atlases[2] = {0, 0};   // sRGB8 and float array textures
    std::vector<std::string> warnings;
    int programs_compiled = 0, programs_reused = 0;
    double compile_seconds = 0.0;
    GLuint film = 0, counters = 0, pixel_stats = 0, photons = 0, hash = 0, radius_stats = 0;
    GLuint direct_light = 0, photon_paths = 0, materials = 0, emitter_records = 0;
    PassLayout pass_layout;  // render passes beside Combined; none: no pass_films buffer
    GLuint pass_films = 0;
    std::size_t geometry_triangles = 0;  // the prepared geometry's, area lights included
    std::size_t material_count = 0;
    std::vector<bool> textures_used;     // TextureUse::used of the prepared scene
    int camera_updates = 0, table_updates = 0, film_resets = 0;

    const gl::ComputeProgram* eye = nullptr;
    const gl::ComputeProgram* photon = nullptr;
    const gl::ComputeProgram* hash_clear = nullptr;
    const gl::ComputeProgram* hash_a = nullptr;   // insert / count
    const gl::ComputeProgram* hash_b = nullptr;   // winner / scatter
    const gl::ComputeProgram* scan[3] = {nullptr, nullptr, nullptr};
    const gl::ComputeProgram* gather = nullptr;
    const gl::ComputeProgram* end_pass = nullptr;
    const gl::ComputeProgram* restart = nullptr;  // a film's first state
    const gl::ComputeProgram* resolve = nullptr;
    const gl::ComputeProgram* radius_reduce = nullptr;

    // The largest storage buffer a render may allocate: the driver's (llvmpipe allows
    // 128 MiB); for the per-pixel buffers, less where settings.max_block_bytes caps it.
    // 0: no limit known.
    std::size_t largest_block(bool per_pixel) const {
        GLint64 largest = 0;
        glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &largest);
        return per_pixel ? capped_block_bytes(largest, settings)
                         : static_cast<std::size_t>(std::max<GLint64>(largest, 0));
    }

    // Before anything is allocated for it: a buffer larger than the driver allows is an
    // error that says what to lower.
    void require_fits(std::size_t bytes, const char* what, bool per_pixel = false) const {
        const std::size_t largest = largest_block(per_pixel);
        if (largest > 0 && bytes > largest)
            throw gl::GlError(std::string(what) + " needs " + std::to_string(bytes >> 20) +
                              " MiB, more than this GPU's largest storage buffer (" +
                              std::to_string(largest >> 20) +
                              " MiB): lower the resolution or the photons per pass, or render "
                              "in tiles (render_tiled, glslppm-render)");
    }

    GLuint make_buffer(GLuint binding, std::size_t bytes, const void* data, const char* what) {
        throw_if_cancelled(setup_cancel);  // large uploads take a while on llvmpipe
        GLuint id = 0;
        glGenBuffers(1, &id);
        gl::count_gl_objects(gl::GlObject::Buffer, 1);
        buffers.push_back(id);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, id);
        while (glGetError() != GL_NO_ERROR) {
        }
        require_fits(bytes, what);
        glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(std::max<std::size_t>(bytes, 16)),
                     data, GL_DYNAMIC_COPY);
        if (glGetError() == GL_OUT_OF_MEMORY)
            throw gl::GlError("out of GPU memory allocating " + std::string(what) + " (" +
                              std::to_string(bytes >> 20) + " MiB): lower the resolution or "
                              "the photons per pass");
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, id);
        gpu_bytes += bytes;
        return id;
    }

    void release() {
        reader.release();
        if (!buffers.empty()) glDeleteBuffers(static_cast<GLsizei>(buffers.size()), buffers.data());
        gl::count_gl_objects(gl::GlObject::Buffer, -static_cast<std::int64_t>(buffers.size()));
        buffers.clear();
        if (ubo) {
            glDeleteBuffers(1, &ubo);
            gl::count_gl_objects(gl::GlObject::Buffer, -1);
        }
        ubo = 0;
        if (queries[0]) {
            glDeleteQueries(5, queries);
            gl::count_gl_objects(gl::GlObject::Query, -5);
        }
        queries[0] = 0;
        if (atlases[0]) {
            glDeleteTextures(2, atlases);
            gl::count_gl_objects(gl::GlObject::Texture, -2);
        }
        atlases[0] = atlases[1] = 0;
    }

    // The images as two array textures on units 0 (sRGB8) and 1 (float); 1x1 placeholders
    // when a kind is absent, so that every sampler is complete.
    void upload_atlas(const TextureAtlas& atlas) {
        glGenTextures(2, atlases);
        gl::count_gl_objects(gl::GlObject::Texture, 2);
        for (int e = 0; e < 2; ++e) {
            const bool has = atlas.layers[e] > 0;
            const glm::ivec2 size = has ? atlas.layer_size[e] : glm::ivec2(1);
            const int layers = has ? atlas.layers[e] : 1;
            glActiveTexture(GL_TEXTURE0 + e);
            glBindTexture(GL_TEXTURE_2D_ARRAY, atlases[e]);
            while (glGetError() != GL_NO_ERROR) {
            }
            glTexStorage3D(GL_TEXTURE_2D_ARRAY, 1, e == 0 ? GL_SRGB8_ALPHA8 : GL_RGBA32F, size.x,
                           size.y, layers);
            if (glGetError() != GL_NO_ERROR)
                throw gl::GlError("out of GPU memory for the scene's images (" +
                                  std::to_string(layers) + " layers of " + std::to_string(size.x) +
                                  "x" + std::to_string(size.y) + "): use fewer or smaller images");
            glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
            if (has) {
                glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
                glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, 0, size.x, size.y, layers, GL_RGBA,
                                e == 0 ? GL_UNSIGNED_BYTE : GL_FLOAT,
                                e == 0 ? static_cast<const void*>(atlas.srgb8.data())
                                       : static_cast<const void*>(atlas.linear.data()));
                gpu_bytes += std::size_t(size.x) * size.y * layers * (e == 0 ? 4 : 16);
            }
        }
        glActiveTexture(GL_TEXTURE0);
    }

    void dispatch(const gl::ComputeProgram& program, std::uint32_t threads) {
        program.use();
        const std::uint32_t groups = (threads + kLocalSize - 1) / kLocalSize;
        if (groups <= 65535u) {
            glDispatchCompute(std::max(groups, 1u), 1, 1);
        } else {
            const std::uint32_t x = 32768u;
            glDispatchCompute(x, (groups + x - 1) / x, 1);
        }
    }

    void set_rng_seed(const gl::ComputeProgram& program, std::uint64_t pass_index,
                      std::uint32_t stage) {
        const GLint location = program.uniform("u_rng_seed");
        if (location >= 0) {
            program.use();
            glUniform1ui(location, mix_seed(settings.seed, pass_index, stage));
        }
    }

    void upload_frame() {
        glBindBuffer(GL_UNIFORM_BUFFER, ubo);
        glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof(FrameBlock), &frame);
    }

    void mark(int stage) {
        if (settings.profile) glQueryCounter(queries[stage], GL_TIMESTAMP);
    }

    // PPPM: pass `pass_index`'s radius r_1 s(i), its estimate's factor and the hash cells
    // of that radius, from the index alone.
    void begin_pppm_pass(std::uint64_t pass_index) {
        const float r = pppm_pass_radius(initial_radius, frame.radius_floor, pass_index,
                                         settings.alpha);
        frame.pass_radius = r;
        // Every photon thread starts one path per pass (photon_trace.comp): N_emitted.
        frame.pass_scale = static_cast<float>(
            1.0 / (3.14159265358979323846 * double(r) * double(r) * double(photon_threads)));
        // The hash grid's cells take r (hash_cell_size() in common/hash_grid.glsl).
    }

    // One pass as its stages. SPPM: pass_index is the count of passes run before. PPPM: any
    // index; the photon paths are traced in max_bounces + 1 steps (a photon may land a
    // (max_bounces + 1)th time: common/bounces.glsl), stored side by side and hashed
    // and gathered steps_per_gather at a time.
    void run_pass(std::uint64_t pass_index) {
        const GLbitfield ssbo = GL_SHADER_STORAGE_BARRIER_BIT;
        const bool pppm = settings.estimator == Estimator::Pppm;
        frame.pass_index = static_cast<std::uint32_t>(pass_index);
        frame.photon_step = 0;
        if (pppm) begin_pppm_pass(pass_index);
        upload_frame();

        mark(0);
        set_rng_seed(*eye, pass_index, 0);
        dispatch(*eye, pixels);
        if (settings.profile) glMemoryBarrier(ssbo);
        mark(1);
        const std::uint32_t steps = pppm ? static_cast<std::uint32_t>(settings.max_bounces) + 1u : 1u;
        const GLsizeiptr slot_bytes = GLsizeiptr(photon_slot) * 3 * 16;
        for (std::uint32_t step = 0; step < steps; ++step) {
            const std::uint32_t slot = step % steps_per_gather;
            if (step > 0) {
                frame.photon_step = step;
                upload_frame();
            }
            if (pppm)
                glBindBufferRange(GL_SHADER_STORAGE_BUFFER, BINDING_PHOTONS, photons,
                                  slot * slot_bytes, slot_bytes);
            set_rng_seed(*photon, pass_index, 1u + (step << 8));
            dispatch(*photon, photon_threads);
            // Storage barriers only within a pass: the host writes nothing but the frame's
            // uniform block, which no shader writes (a buffer-update barrier here cost a
            // host wait for the GPU per step on NVIDIA, and one device's wait blocked the
            // other devices' threads).
            glMemoryBarrier(ssbo);
            if (step == 0) mark(2);
            if (slot + 1 < steps_per_gather && step + 1 < steps) continue;
            if (!pppm) {
                hash_and_gather(true, photon_threads);
                continue;
            }
            // The steps stored so far, hashed and gathered as one set of photons.
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, BINDING_PHOTONS, photons);
            const std::uint32_t stored = (slot + 1) * photon_slot;
            frame.photon_threads = stored;
            upload_frame();
            hash_and_gather(step + 1 == steps_per_gather || step + 1 == steps, stored);
            frame.photon_threads = photon_threads;
            upload_frame();
        }
        end_pass->use();
        glDispatchCompute(1, 1, 1);
        glMemoryBarrier(ssbo);
        mark(4);
        ++passes;
        if (settings.profile) {
            GLuint64 t[5];
            for (int k = 0; k < 5; ++k) glGetQueryObjectui64v(queries[k], GL_QUERY_RESULT, &t[k]);
            for (int k = 0; k < 4; ++k) stage_seconds[k] += 1e-9 * static_cast<double>(t[k + 1] - t[k]);
        }
    }

    void hash_and_gather(bool mark_stages, std::uint32_t stored) {
        const GLbitfield ssbo = GL_SHADER_STORAGE_BARRIER_BIT;

        dispatch(*hash_clear, hash_cells);
        glMemoryBarrier(ssbo);
        dispatch(*hash_a, stored);
        glMemoryBarrier(ssbo);
        if (settings.hash == HashMode::Exact) {
            const std::uint32_t blocks = hash_cells / 1024u;
            scan[0]->use();
            glDispatchCompute(blocks, 1, 1);
            glMemoryBarrier(ssbo);
            scan[1]->use();
            glDispatchCompute(1, 1, 1);
            glMemoryBarrier(ssbo);
            scan[2]->use();
            glDispatchCompute(blocks, 1, 1);
            glMemoryBarrier(ssbo);
        }
        dispatch(*hash_b, stored);
        glMemoryBarrier(ssbo);
        if (mark_stages) mark(3);
        dispatch(*gather, pixels);
        glMemoryBarrier(ssbo);
    }

    // The film of this worker's passes (their mean), read back.
    std::vector<float> resolve_film() {
        std::vector<float> out(std::size_t(pixels) * 4, 0.0f);
        resolve_film_into(out.data());
        return out;
    }

    // The same into `out` (pixels x 4 floats); bottom_up: its bottom row first.
    void resolve_film_into(float* out, bool bottom_up = false) {
        const Counters c = read_counters();
        const std::uint64_t emitted = total(c.emitted_lo, c.emitted_hi);
        frame.inv_passes = passes ? 1.0f / static_cast<float>(passes) : 0.0f;
        frame.inv_photons_emitted = emitted ? static_cast<float>(1.0 / static_cast<double>(emitted)) : 0.0f;
        upload_frame();
        dispatch(*resolve, pixels);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        reader.read(film, 0, std::size_t(pixels) * 16, out,
                    bottom_up ? std::size_t(settings.width) * 16 : 0);
    }

    // Render passes of this worker's passes (their mean), resolved on the CPU from the pass
    // films and the pixel statistics, as resolve_film() resolves Combined on the GPU: one
    // read back for all of them.
    std::vector<std::vector<float>> resolve_passes(const std::vector<RenderPass>& wanted) {
        std::vector<glm::vec4> films(std::size_t(pixels) * pass_layout.stride);
        std::vector<glm::vec4> stats(std::size_t(pixels) * 2);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        reader.read(pass_films, 0, films.size() * 16, films.data());
        reader.read(pixel_stats, 0, stats.size() * 16, stats.data());
        const Counters c = read_counters();
        const std::uint64_t emitted = total(c.emitted_lo, c.emitted_hi);
        PassResolve r;
        r.inv_passes = passes ? 1.0f / static_cast<float>(passes) : 0.0f;
        r.inv_photons_emitted =
            emitted ? static_cast<float>(1.0 / static_cast<double>(emitted)) : 0.0f;
        r.pppm = settings.estimator == Estimator::Pppm;
        std::vector<std::vector<float>> images;
        for (RenderPass pass : wanted)
            images.push_back(resolve_render_pass(pass_layout, pass, films, stats, pixels, r));
        return images;
    }

    // The film's first state (a new renderer, a restart): no passes, every pixel's radius
    // the initial one, no direct light, every photon path to start from a light, counts
    // zero. Written by a dispatch (restart_film.comp): the host uploads nothing.
    void restart_film() {
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        restart->use();
        glUniform1ui(restart->uniform("u_pixels"), pixels);
        glUniform1ui(restart->uniform("u_photon_threads"), photon_threads);
        glUniform1f(restart->uniform("u_initial_radius"), initial_radius);
        dispatch(*restart, std::max(pixels, photon_threads));
        if (pass_films) {
            // A clear after shader writes takes a buffer-update barrier: a restart is not a
            // pass, so its host wait does not slow the passes.
            glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
            const GLuint zero[4] = {0u, 0u, 0u, 0u};
            glBindBuffer(GL_SHADER_STORAGE_BUFFER, pass_films);
            glClearBufferData(GL_SHADER_STORAGE_BUFFER, GL_RGBA32UI, GL_RGBA_INTEGER,
                              GL_UNSIGNED_INT, zero);
        }
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
        passes = 0;
        pass_indices.clear();  // PPPM: a restarted film has run no pass index
        seconds = submit_seconds = wait_seconds = 0.0;
        std::fill(std::begin(stage_seconds), std::end(stage_seconds), 0.0);
    }

    // Replaces a buffer's contents, its size too (a table that grew or shrank).
    void replace_buffer(GLuint id, std::size_t bytes, const void* data, const char* what) {
        require_fits(bytes, what);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, id);
        glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(std::max<std::size_t>(bytes, 16)),
                     data, GL_DYNAMIC_COPY);
    }

    Counters read_counters() {
        Counters c{};
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, counters);
        glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, sizeof(Counters), &c);
        return c;
    }

    static std::uint64_t total(std::uint32_t lo, std::uint32_t hi) {
        return (static_cast<std::uint64_t>(hi) << 32) | lo;
    }
};

}  // namespace glslppm
