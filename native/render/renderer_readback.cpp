// What a Renderer reads back: the film (merged over the workers), render passes, the last
// pass's photons and the stats.
#include "render/renderer.h"
#include "render/pipeline.h"

#include <algorithm>
#include <stdexcept>

#include <epoxy/gl.h>

#include "render/film_merge.h"
#include "render/gpu_layout.h"

namespace glslppm {

std::vector<float> Renderer::Gpu::resolve_film() {
    std::vector<float> out(std::size_t(scene.pixels) * 4, 0.0f);
    resolve_film_into(out.data());
    return out;
}

void Renderer::Gpu::resolve_film_into(float* out, bool bottom_up) {
    const Counters c = read_counters();
    const std::uint64_t emitted = total(c.emitted_lo, c.emitted_hi);
    FrameBlock& frame = scene.frame;
    frame.inv_passes = passes ? 1.0f / static_cast<float>(passes) : 0.0f;
    frame.inv_photons_emitted = emitted ? static_cast<float>(1.0 / static_cast<double>(emitted)) : 0.0f;
    upload_frame();
    dispatch(*programs.resolve, scene.pixels);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    buffers.reader.read(buffers.film, 0, std::size_t(scene.pixels) * 16, out,
                        bottom_up ? std::size_t(settings.width) * 16 : 0);
}

std::vector<std::vector<float>> Renderer::Gpu::resolve_passes(const std::vector<RenderPass>& wanted,
                                                              bool groups) {
    const std::uint32_t pixels = scene.pixels;
    const PassLayout& layout = scene.pass_layout;
    std::vector<glm::vec4> films(std::size_t(pixels) * layout.stride);
    std::vector<glm::vec4> stats(std::size_t(pixels) * 2);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    buffers.reader.read(buffers.pass_films, 0, films.size() * 16, films.data());
    buffers.reader.read(buffers.pixel_stats, 0, stats.size() * 16, stats.data());
    const Counters c = read_counters();
    const std::uint64_t emitted = total(c.emitted_lo, c.emitted_hi);
    PassResolve r;
    r.inv_passes = passes ? 1.0f / static_cast<float>(passes) : 0.0f;
    r.inv_photons_emitted =
        emitted ? static_cast<float>(1.0 / static_cast<double>(emitted)) : 0.0f;
    r.mean_of_passes = density_estimator(settings.estimator).film == FilmResolve::MeanOfPasses;
    std::vector<std::vector<float>> images;
    for (RenderPass pass : wanted)
        images.push_back(resolve_render_pass(layout, pass, films, stats, pixels, r));
    for (int group = 0; groups && group < layout.light_groups; ++group)
        images.push_back(resolve_light_group(layout, group, films, stats, pixels, r));
    if (groups && buffers.light_splats) {
        // Light tracing's splats of each group: its block after the frame's
        // (common/light_splats.glsl), as resolve_film.comp adds Combined's.
        const std::size_t block = std::size_t(pixels) * kLightSplatBytes;
        std::vector<std::uint32_t> words(block / 4);
        const FrameBlock& f = scene.frame;
        const float pixel_area = 4.0f * f.film_half_extent.x * f.film_half_extent.y /
                                 (float(f.image_width) * float(f.image_height));
        const float scale = r.mean_of_passes ? r.inv_passes : r.inv_photons_emitted;
        const std::size_t first = images.size() - std::size_t(layout.light_groups);
        for (int group = 0; group < layout.light_groups; ++group) {
            buffers.reader.read(buffers.light_splats, (std::size_t(group) + 1) * block, block,
                                words.data());
            add_light_group_splats(images[first + std::size_t(group)], words, scale, pixel_area);
        }
    }
    return images;
}

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
        if (gpus_[0]->scene.pass_layout.offset(pass) < 0)
            throw std::invalid_argument(std::string("render pass '") +
                                        render_pass_info(pass).name +
                                        "' was not enabled: add it to the settings' passes");
    return merged_passes(wanted, false);
}

std::vector<std::vector<float>> Renderer::light_group_passes() {
    if (light_groups_.empty()) return {};
    return merged_passes({}, true);
}

std::vector<std::vector<float>> Renderer::merged_passes(const std::vector<RenderPass>& wanted,
                                                        bool groups) {
    // As film(): each worker's pass is the mean of its passes, merged by their counts.
    std::vector<std::vector<std::vector<float>>> per_worker;  // worker, pass, pixels
    std::vector<std::uint64_t> passes;
    for (auto& g : gpus_) {
        g->thread->call([&] {
            per_worker.push_back(g->resolve_passes(wanted, groups));
            passes.push_back(g->passes);
        });
    }
    if (per_worker.size() == 1) return std::move(per_worker[0]);
    std::vector<std::vector<float>> merged;
    for (std::size_t k = 0; k < per_worker[0].size(); ++k) {
        std::vector<const std::vector<float>*> views;
        for (const auto& worker : per_worker) views.push_back(&worker[k]);
        merged.push_back(merge_films(views, passes));
    }
    return merged;
}

std::vector<float> Renderer::photons() {
    Gpu& g = *gpus_[0];
    std::vector<float> out(std::size_t(g.scene.photon_threads) * 12, 0.0f);
    g.thread->call([&] {
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        g.buffers.reader.read(g.buffers.photons, 0, out.size() * 4, out.data());
    });
    return out;
}

RenderStats Renderer::stats() {
    RenderStats s;
    std::vector<glm::vec2> radius_stats(kRadiusStatsThreads);
    std::vector<std::uint64_t> indices;
    const DensityEstimator& estimator = density_estimator(settings_.estimator);
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
            if (estimator.independent_passes)
                indices.insert(indices.end(), w.pass_indices.begin(), w.pass_indices.end());
            if (!estimator.pass_radius_of) {
                // Each pixel's own radius, reduced on the GPU: a few KiB read back, not every
                // pixel's statistics.
                w.programs.radius_reduce->use();
                glDispatchCompute(1, 1, 1);
                glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
                glBindBuffer(GL_SHADER_STORAGE_BUFFER, w.buffers.radius_stats);
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
    s.radius_floor = g.scene.frame.radius_floor;
    s.estimator = to_string(settings_.estimator);
    s.scene_hash = scene_hash_;
    if (estimator.independent_passes)
        s.pass_ranges = pass_ranges(indices);
    else if (s.passes)
        s.pass_ranges.push_back({0, s.passes});
    if (estimator.pass_radius_of) {
        // Every pixel has the pass's radius: that of the latest pass index run.
        const std::uint64_t last = s.pass_ranges.empty() ? settings_.first_pass
                                                         : s.pass_ranges.back().second - 1;
        s.mean_radius = s.max_radius = estimator.pass_radius_of(
            g.scene.initial_radius, g.scene.frame.radius_floor, last, settings_.alpha);
    } else {
        double sum = 0.0, largest = 0.0;
        for (const glm::vec2& t : radius_stats) {
            sum += t.x;
            largest = std::max(largest, static_cast<double>(t.y));
        }
        s.mean_radius = g.scene.pixels ? sum / g.scene.pixels : 0.0;
        s.max_radius = largest;
    }
    s.initial_radius = g.scene.initial_radius;
    s.renderer = g.thread->info().renderer;
    s.variant = g.scene.variant;
    s.direct_light = to_string(g.settings.direct_light);
    s.triangles = g.bvh_stats.triangles;
    s.degenerate_dropped = g.bvh_stats.degenerate_dropped;
    s.instancing = g.scene.instancing.path;
    s.instancing_reason = g.scene.instancing.reason;
    s.instances = g.scene.instance_count;
    s.instanced_triangles = g.scene.instancing.instanced_triangles;
    if (const MotionPlan* m = g.scene.motion.get()) {
        std::string parts = m->camera ? "camera" : "";
        if (!m->instances.empty()) parts += parts.empty() ? "instances" : ",instances";
        if (!m->meshes.empty()) parts += parts.empty() ? "deformation" : ",deformation";
        if (!m->lights.empty()) parts += parts.empty() ? "lights" : ",lights";
        if (!m->mesh_emitters.empty()) parts += parts.empty() ? "emitters" : ",emitters";
        s.motion = parts;
        s.moving_instances = m->instances.size();
        for (const auto& w : gpus_) s.motion_refit_seconds += w->motion.refit_seconds;
    }
    s.emitters = g.scene.emitters.count;
    s.bvh_seconds = g.bvh_stats.total_seconds();
    s.bvh_bytes_per_triangle = g.bvh_stats.bytes_per_triangle;
    for (const auto& w : gpus_) s.gpu_bytes += w->buffers.bytes;
    s.gpu_bytes_per_pixel = g.buffers.bytes_per_pixel;
    s.gpu_bytes_per_photon = g.buffers.bytes_per_photon;
    s.pass_state_bytes = g.buffers.pass_state_bytes;
    s.eye_seconds = g.timer.seconds[0];
    s.photon_seconds = g.timer.seconds[1];
    s.hash_seconds = g.timer.seconds[2];
    s.gather_seconds = g.timer.seconds[3];
    s.warnings = g.scene.warnings;
    s.programs_compiled = g.programs.compiled;
    s.programs_reused = g.programs.reused;
    s.compile_seconds = g.programs.compile_seconds;
    s.camera_updates = g.camera_updates;
    s.table_updates = g.table_updates;
    s.film_resets = g.film_resets;
    return s;
}

}  // namespace glslppm
