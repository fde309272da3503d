// What a Renderer reads back: the film (merged over the workers), render passes, the last
// pass's photons and the stats.
#include "render/renderer.h"
#include "render/pipeline.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cstddef>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <future>
#include <optional>
#include <stdexcept>

#include <epoxy/gl.h>

#include "gl/object_counts.h"
#include "gl/egl_context.h"
#include "bvh/packed_bvh.h"
#include "bvh/traverse_cpu.h"
#include "gl/gl_thread.h"
#include "gl/shader_program.h"
#include "render/area_lights.h"
#include "render/emitters.h"
#include "render/environment_map.h"
#include "render/gpu_layout.h"
#include "render/scene_preparation.h"
#include "render/texture_atlas.h"
#include "render/rng_seed.h"
#include "render/film_merge.h"
#include "render/pppm_schedule.h"
#include "scene/scene_hash.h"
#include "scene/scene_validation.h"

namespace glslppm {

std::vector<float> Renderer::film() {
    if (gpus_.size() == 1) {
        Gpu& g = *gpus_[0];
        return g.thread->call([&] { return g.resolve_film(); });
    }
    return merged_film();
}

void Renderer::film_into(std::span<float> out, bool bottom_up) {
    const std::size_t floats = std::size_t(settings_.width) * std::size_t(settings_.height) * 4;
    if (out.size() != floats)
        throw std::invalid_argument("film_into: the buffer holds " + std::to_string(out.size()) +
                                    " floats; the film is " + std::to_string(floats));
    if (gpus_.size() == 1) {
        Gpu& g = *gpus_[0];
        g.thread->call([&] { g.resolve_film_into(out.data(), bottom_up); });
        return;
    }
    const std::vector<float> merged = merged_film();
    const std::size_t row = std::size_t(settings_.width) * 4;
    for (std::size_t y = 0; y < std::size_t(settings_.height); ++y) {
        const std::size_t to = bottom_up ? std::size_t(settings_.height) - 1 - y : y;
        std::copy_n(merged.begin() + std::ptrdiff_t(y * row), row,
                    out.begin() + std::ptrdiff_t(to * row));
    }
}

std::vector<float> Renderer::merged_film() {
    // Each worker's film is the mean of its passes; merged by their counts.
    std::vector<std::vector<float>> films;
    std::vector<std::uint64_t> passes;
    for (auto& g : gpus_) {
        g->thread->call([&] {
            films.push_back(g->resolve_film());
            passes.push_back(g->passes);
        });
    }
    std::vector<const std::vector<float>*> views;
    for (const auto& f : films) views.push_back(&f);
    return merge_films(views, passes);
}

std::vector<float> Renderer::render_pass(RenderPass pass) {
    return std::move(render_passes({pass})[0]);
}

std::vector<std::vector<float>> Renderer::render_passes(const std::vector<RenderPass>& wanted) {
    for (RenderPass pass : wanted)
        if (gpus_[0]->pass_layout.offset(pass) < 0)
            throw std::invalid_argument(std::string("render pass '") +
                                        render_pass_info(pass).name +
                                        "' was not enabled: add it to the settings' passes");
    // As film(): each worker's pass is the mean of its passes, merged by their counts.
    std::vector<std::vector<std::vector<float>>> per_worker;  // worker, pass, pixels
    std::vector<std::uint64_t> passes;
    for (auto& g : gpus_) {
        g->thread->call([&] {
            per_worker.push_back(g->resolve_passes(wanted));
            passes.push_back(g->passes);
        });
    }
    if (per_worker.size() == 1) return std::move(per_worker[0]);
    std::vector<std::vector<float>> merged;
    for (std::size_t k = 0; k < wanted.size(); ++k) {
        std::vector<const std::vector<float>*> views;
        for (const auto& worker : per_worker) views.push_back(&worker[k]);
        merged.push_back(merge_films(views, passes));
    }
    return merged;
}

std::vector<float> Renderer::photons() {
    Gpu& g = *gpus_[0];
    std::vector<float> out(std::size_t(g.photon_threads) * 12, 0.0f);
    g.thread->call([&] {
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        g.reader.read(g.photons, 0, out.size() * 4, out.data());
    });
    return out;
}

RenderStats Renderer::stats() {
    RenderStats s;
    std::vector<glm::vec2> radius_stats(kRadiusStatsThreads);
    std::vector<std::uint64_t> indices;
    const bool pppm = settings_.estimator == Estimator::Pppm;
    for (std::size_t k = 0; k < gpus_.size(); ++k) {
        Gpu& w = *gpus_[k];
        DeviceStats d;
        Counters c{};
        w.thread->call([&] {
            // One consistent snapshot: runs change these on this thread only.
            d.passes = w.passes;
            d.seconds = w.seconds;
            d.submit_seconds = w.submit_seconds;
            d.wait_seconds = w.wait_seconds;
            c = w.read_counters();
            if (pppm) {
                indices.insert(indices.end(), w.pass_indices.begin(), w.pass_indices.end());
            } else {
                // The radii reduced on the GPU: a few KiB read back, not every pixel's
                // statistics.
                w.radius_reduce->use();
                glDispatchCompute(1, 1, 1);
                glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
                glBindBuffer(GL_SHADER_STORAGE_BUFFER, w.radius_stats);
                glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0,
                                   static_cast<GLsizeiptr>(radius_stats.size() * sizeof(glm::vec2)),
                                   radius_stats.data());
            }
        });
        d.device = w.thread->info().device_index;
        d.renderer = w.thread->info().renderer;
        d.passes_per_second = d.seconds > 0 ? static_cast<double>(d.passes) / d.seconds : 0.0;
        s.passes += d.passes;
        s.photons_emitted += Gpu::total(c.emitted_lo, c.emitted_hi);
        s.rays += Gpu::total(c.rays_lo, c.rays_hi);
        s.devices.push_back(d);
    }
    Gpu& g = *gpus_[0];
    s.seconds = gpus_.size() == 1 ? g.seconds : seconds_;
    s.photons_per_second = s.seconds > 0 ? static_cast<double>(s.photons_emitted) / s.seconds : 0;
    s.rays_per_second = s.seconds > 0 ? static_cast<double>(s.rays) / s.seconds : 0;
    s.radius_floor = g.frame.radius_floor;
    s.estimator = to_string(settings_.estimator);
    s.scene_hash = scene_hash_;
    if (pppm) {
        // Every pixel has the pass's radius: that of the latest pass index run.
        s.pass_ranges = pass_ranges(indices);
        const std::uint64_t last = s.pass_ranges.empty() ? settings_.first_pass
                                                         : s.pass_ranges.back().second - 1;
        s.mean_radius = s.max_radius = pppm_pass_radius(g.initial_radius, g.frame.radius_floor,
                                                        last, settings_.alpha);
    } else {
        double sum = 0.0, largest = 0.0;
        for (const glm::vec2& t : radius_stats) {
            sum += t.x;
            largest = std::max(largest, static_cast<double>(t.y));
        }
        s.mean_radius = g.pixels ? sum / g.pixels : 0.0;
        s.max_radius = largest;
        if (s.passes) s.pass_ranges.push_back({0, s.passes});
    }
    s.initial_radius = g.initial_radius;
    s.renderer = g.thread->info().renderer;
    s.variant = g.variant;
    s.direct_light = to_string(g.settings.direct_light);
    s.triangles = g.bvh.stats.triangles;
    s.degenerate_dropped = g.bvh.stats.degenerate_dropped;
    s.instancing = g.instancing.path;
    s.instancing_reason = g.instancing.reason;
    s.instances = g.instance_count;
    s.instanced_triangles = g.instancing.instanced_triangles;
    s.emitters = g.emitters.count;
    s.bvh_seconds = g.bvh.stats.total_seconds();
    s.bvh_bytes_per_triangle = g.bvh.stats.bytes_per_triangle;
    for (const auto& w : gpus_) s.gpu_bytes += w->gpu_bytes;
    s.gpu_bytes_per_pixel = g.gpu_bytes_per_pixel;
    s.gpu_bytes_per_photon = g.gpu_bytes_per_photon;
    s.eye_seconds = g.stage_seconds[0];
    s.photon_seconds = g.stage_seconds[1];
    s.hash_seconds = g.stage_seconds[2];
    s.gather_seconds = g.stage_seconds[3];
    s.warnings = g.warnings;
    s.programs_compiled = g.programs_compiled;
    s.programs_reused = g.programs_reused;
    s.compile_seconds = g.compile_seconds;
    s.camera_updates = g.camera_updates;
    s.table_updates = g.table_updates;
    s.film_resets = g.film_resets;
    return s;
}

}  // namespace glslppm
