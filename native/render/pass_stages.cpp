// One pass as its stages, in the order the GPU runs them (render/pipeline.h): the eye paths
// find visible points, the photon paths trace one bounce and store a photon, the photons are
// hashed, each visible point gathers and updates its estimate, and the pass is counted.
#include <algorithm>
#include <iterator>

#include "render/density_estimator.h"
#include "render/pipeline.h"

namespace glslppm {

// The estimator's differences (render/density_estimator.h): the pass's radius (begin_pass),
// how many photon steps a pass traces and whether they are stored side by side before the
// hash and gather.
void Renderer::Gpu::run_pass(std::uint64_t pass_index) {
    const DensityEstimator& estimator = density_estimator(settings.estimator);
    begin_pass(pass_index);
    if (estimator.photon_paths == PhotonPaths::AcrossPasses && passes == 0 &&
        settings.photon_warm_up)
        warm_up_photon_paths();
    trace_eye(pass_index);
    // VCM's light subpaths (common/vcm_light_paths.glsl): each traced whole in one dispatch;
    // with vertex merging, the photons they stored hashed and gathered at the eye paths'
    // visible points (common/vcm_merging.glsl).
    if (estimator.photon_paths == PhotonPaths::NoPhotons && programs.light_splats) {
        trace_photons(pass_index, 0);
        if (vcm_merges(settings.vcm_techniques)) gather_stored_steps(steps_per_gather, true);
    }
    const std::uint32_t steps = estimator.photon_steps_per_pass(settings.max_bounces);
    for (std::uint32_t step = 0; step < steps; ++step) {
        const std::uint32_t slot = step % steps_per_gather;
        trace_photons(pass_index, step);
        if (slot + 1 < steps_per_gather && step + 1 < steps) continue;  // a slot still free
        if (estimator.photon_paths == PhotonPaths::AcrossPasses) {
            hash_photons(scene.photon_threads);
            gather(true);
        } else {
            gather_stored_steps(slot + 1, step + 1 == steps_per_gather || step + 1 == steps);
        }
    }
    end_pass();
}

// The frame's pass constants. An estimator with a radius per pass (PPPM): pass
// `pass_index`'s radius r_1 s(i), its estimate's factor and the hash cells of that radius,
// from the index alone.
void Renderer::Gpu::begin_pass(std::uint64_t pass_index) {
    const DensityEstimator& estimator = density_estimator(settings.estimator);
    FrameBlock& frame = scene.frame;
    frame.pass_index = static_cast<std::uint32_t>(pass_index);
    frame.photon_step = 0;
    if (scene.motion) move_to_shutter_time(pass_index);
    if (estimator.pass_radius_of) {
        const PassRadius pass =
            estimator.pass_radius(scene.initial_radius, frame.radius_floor, pass_index,
                                  settings.alpha, scene.photon_threads);
        frame.pass_radius = pass.radius;
        frame.pass_scale = pass.scale;
        // The hash grid's cells take r (hash_cell_size() in common/hash_grid.glsl).
    }
    upload_frame();
}

// eye_trace.comp: each pixel's eye path to its visible point.
void Renderer::Gpu::trace_eye(std::uint64_t pass_index) {
    mark(0);
    set_merge_slots(*programs.eye);
    set_rng_seed(*programs.eye, pass_index, 0);
    dispatch(*programs.eye, scene.pixels);
    if (settings.profile) glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    mark(1);
}

// photon_trace.comp: one bounce of every photon path. PhotonPaths::WithinPass: step `step`
// of the pass, stored in its slot of the photon buffer.
void Renderer::Gpu::trace_photons(std::uint64_t pass_index, std::uint32_t step) {
    if (step > 0) {
        scene.frame.photon_step = step;
        upload_frame();
    }
    if (density_estimator(settings.estimator).photon_paths == PhotonPaths::WithinPass) {
        const GLsizeiptr slot_bytes = GLsizeiptr(photon_slot * kPhotonBytes);
        glBindBufferRange(GL_SHADER_STORAGE_BUFFER, BINDING_PHOTONS, buffers.photons,
                          (step % steps_per_gather) * slot_bytes, slot_bytes);
    }
    set_rng_seed(*programs.photon, pass_index, 1u + (step << 8));
    set_merge_slots(*programs.photon);
    dispatch(*programs.photon, scene.photon_threads);
    // Storage barriers only within a pass: the host writes nothing but the frame's uniform
    // block, which no shader writes (a buffer-update barrier here cost a host wait for the
    // GPU per step on NVIDIA, and one device's wait blocked the other devices' threads).
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    if (step == 0) mark(2);
}

// Paths carried across passes (SPPM) start a film near their stationary state: the photons
// in flight when a render stops have not yet left their later bounces, a bias of minus their
// expected deposits over the paths started (-0.65% at 400 passes of the Cornell box, -3% at
// 100: docs/cornell_vs_cycles.md). By the renewal-reward theorem E[deposits] / E[paths
// started] over the passes is exact where the paths' states are stationary; the state after
// k steps from a fresh start tends to it geometrically (at once where a path's end does not
// depend on its age, as in a diffuse furnace). So photon steps that store nothing and whose
// started paths are not counted run first: max_bounces + 1 (a path's longest), at most
// kWarmUpSteps, which costs about as many photon stages and bounds the cost of a restart
// (the viewport's) where max_bounces is large. Their random numbers are pass 0's, of their
// own stage.
constexpr std::uint32_t kWarmUpSteps = 16;

void Renderer::Gpu::warm_up_photon_paths() {
    const gl::ComputeProgram& photon = *programs.photon;
    photon.use();
    glUniform1ui(photon.uniform("u_warm_up"), 1u);
    const std::uint32_t steps =
        std::min(static_cast<std::uint32_t>(std::max(settings.max_bounces, 0)) + 1u, kWarmUpSteps);
    for (std::uint32_t step = 0; step < steps; ++step) {
        set_rng_seed(photon, 0, 2u + (step << 8));
        dispatch(photon, scene.photon_threads);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
    photon.use();
    glUniform1ui(photon.uniform("u_warm_up"), 0u);
}

// hash_photons.comp: the stored photons into the hash cells (stochastic: one survivor per
// cell and its count; exact: counted, prefix-summed and scattered).
void Renderer::Gpu::hash_photons(std::uint32_t stored) {
    const GLbitfield ssbo = GL_SHADER_STORAGE_BARRIER_BIT;
    dispatch(*programs.hash_clear, scene.hash_cells);
    glMemoryBarrier(ssbo);
    dispatch(*programs.hash_a, stored);
    glMemoryBarrier(ssbo);
    if (settings.hash == HashMode::Exact) {
        const std::uint32_t blocks = scene.hash_cells / 1024u;
        programs.scan[0]->use();
        glDispatchCompute(blocks, 1, 1);
        glMemoryBarrier(ssbo);
        programs.scan[1]->use();
        glDispatchCompute(1, 1, 1);
        glMemoryBarrier(ssbo);
        programs.scan[2]->use();
        glDispatchCompute(blocks, 1, 1);
        glMemoryBarrier(ssbo);
    }
    dispatch(*programs.hash_b, stored);
    glMemoryBarrier(ssbo);
}

// PhotonPaths::WithinPass: the `stored_steps` steps stored side by side so far, hashed and
// gathered as one set of photons.
void Renderer::Gpu::gather_stored_steps(std::uint32_t stored_steps, bool mark_stage) {
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, BINDING_PHOTONS, buffers.photons);
    const std::uint32_t stored = stored_steps * photon_slot;
    scene.frame.photon_threads = stored;
    upload_frame();
    hash_photons(stored);
    gather(mark_stage);
    scene.frame.photon_threads = scene.photon_threads;
    upload_frame();
}

// gather.comp: each visible point's photons and its progressive update.
void Renderer::Gpu::gather(bool mark_stage) {
    if (mark_stage) mark(3);
    dispatch(*programs.gather, scene.pixels);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

// end_pass.comp: the pass's counts into the 64-bit totals (with light tracing, the pass's
// splats into the film's sums first).
void Renderer::Gpu::end_pass() {
    if (programs.light_splats) {
        // light_splats.comp: the pass's fixed-point splats into each pixel's float sum.
        dispatch(*programs.light_splats, scene.pixels);
        glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }
    programs.end_pass->use();
    glDispatchCompute(1, 1, 1);
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    mark(4);
    ++passes;
    if (settings.profile) {
        GLuint64 t[5];
        for (int k = 0; k < 5; ++k) glGetQueryObjectui64v(timer.queries[k], GL_QUERY_RESULT, &t[k]);
        for (int k = 0; k < 4; ++k) timer.seconds[k] += 1e-9 * static_cast<double>(t[k + 1] - t[k]);
    }
}

void Renderer::Gpu::restart_film() {
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    const gl::ComputeProgram& restart = *programs.restart;
    restart.use();
    glUniform1ui(restart.uniform("u_pixels"), scene.pixels);
    glUniform1ui(restart.uniform("u_photon_threads"), scene.photon_threads);
    glUniform1f(restart.uniform("u_initial_radius"), scene.initial_radius);
    dispatch(restart, std::max(scene.pixels, scene.photon_threads));
    // A clear after shader writes takes a buffer-update barrier: a restart is not a pass, so
    // its host wait does not slow the passes.
    for (GLuint buffer : {buffers.pass_films, buffers.light_splats}) {
        if (!buffer) continue;
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        const GLuint zero[4] = {0u, 0u, 0u, 0u};
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffer);
        glClearBufferData(GL_SHADER_STORAGE_BUFFER, GL_RGBA32UI, GL_RGBA_INTEGER, GL_UNSIGNED_INT,
                          zero);
    }
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    passes = 0;
    pass_indices.clear();  // independent passes: a restarted film has run no pass index
    seconds = submit_seconds = wait_seconds = 0.0;
    std::fill(std::begin(timer.seconds), std::end(timer.seconds), 0.0);
}

void Renderer::Gpu::dispatch(const gl::ComputeProgram& program, std::uint32_t threads) {
    program.use();
    const std::uint32_t groups = (threads + kLocalSize - 1) / kLocalSize;
    if (groups <= 65535u) {
        glDispatchCompute(std::max(groups, 1u), 1, 1);
    } else {
        const std::uint32_t x = 32768u;
        glDispatchCompute(x, (groups + x - 1) / x, 1);
    }
}

void Renderer::Gpu::set_rng_seed(const gl::ComputeProgram& program, std::uint64_t pass_index,
                                 std::uint32_t stage) {
    const GLint location = program.uniform("u_rng_seed");
    if (location >= 0) {
        program.use();
        glUniform1ui(location, mix_seed(settings.seed, pass_index, stage));
    }
}

// VCM's merging: the light vertices' slots a path may fill (vcm_merge_slots), which the eye
// paths' weights read as well. The programs are shared between renderers: set every pass.
void Renderer::Gpu::set_merge_slots(const gl::ComputeProgram& program) {
    const GLint location = program.uniform("u_merge_slots");
    if (location >= 0) {
        program.use();
        glUniform1ui(location, steps_per_gather);
    }
}

void Renderer::Gpu::mark(int stage) {
    if (settings.profile) glQueryCounter(timer.queries[stage], GL_TIMESTAMP);
}

}  // namespace glslppm
