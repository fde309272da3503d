// The Renderer: its constructor prepares the scene (render/scene_preparation.h) and sets up
// one pipeline per device (renderer_setup.cpp); runs deal passes to them (a pass is the
// stages of pass_stages.cpp); set_camera, update_tables and reset_film restart them.
#include "render/renderer.h"
#include "render/pipeline.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <future>
#include <optional>
#include <stdexcept>

#include <epoxy/gl.h>

#include "gl/egl_context.h"
#include "scene/scene_hash.h"
#include "scene/scene_validation.h"

namespace glslppm {
namespace {

// The stats of the MTBVH traced: two levels count every mesh once and their build.
BvhStats traced_bvh_stats(const PreparedScene& p) {
    BvhStats st = p.bvh.stats;
    if (!p.two_level) return st;
    const TwoLevelStats& two = p.two_level->stats;
    st.triangles = two.mesh_triangles;
    st.build_seconds += two.bottom_seconds + two.top_seconds;
    st.bytes_total = two.bytes_total;
    st.bytes_per_triangle =
        st.triangles ? static_cast<double>(st.bytes_total) / static_cast<double>(st.triangles) : 0.0;
    return st;
}

}  // namespace

Renderer::Renderer(const Scene& scene, const RenderSettings& settings, const CancelFlag* cancel)
    : settings_(settings), light_groups_(scene.light_groups), next_pass_(settings.first_pass) {
    const std::vector<int> devices =
        settings.devices.empty() ? std::vector<int>{settings.device} : settings.devices;
    // Flattening instances pays up to a larger size on a GPU than on llvmpipe; with several
    // devices, the smallest bound of theirs.
    flatten_max_triangles_ = kFlattenMaxTrianglesGpu;
    for (int device : devices)
        if (gl::is_software_device(device)) flatten_max_triangles_ = kFlattenMaxTrianglesSoftware;
    PreparedScene prepared =
        prepare_scene(scene, settings, kLocalSize, cancel, nullptr, flatten_max_triangles_);
    // The MTBVH traced, one level or two, shared by the workers (each uploads it).
    std::shared_ptr<const PackedBvh> bvh;
    std::shared_ptr<const TwoLevelBvh> two_level;
    const BvhStats bvh_stats = traced_bvh_stats(prepared);
    if (prepared.two_level)
        two_level = std::move(prepared.two_level);
    else
        bvh = std::make_shared<const PackedBvh>(std::move(prepared.bvh));
    scene_hash_without_camera_ = scene_hash_without_camera(scene, cancel);
    scene_hash_ = scene_hash_hex(scene_hash_with_camera(scene_hash_without_camera_, scene.camera));
    try {
        for (int device : devices) {
            gpus_.push_back(std::make_unique<Gpu>());
            Gpu& g = *gpus_.back();
            g.bvh = bvh;
            g.two_level = two_level;
            g.bvh_stats = bvh_stats;
            set_up(g, device, scene, settings, prepared, cancel);
        }
    } catch (...) {
        for (auto& g : gpus_)
            if (g->thread) g->thread->call([&] { g->release(); });
        throw;
    }
}

Renderer::~Renderer() {
    for (auto& g : gpus_) g->cancel = true;  // runs in progress stop after their current pass
    for (auto& g : gpus_)
        if (g->thread) g->thread->call([&] { g->release(); });
}

void Renderer::cancel() {
    for (auto& g : gpus_) g->cancel = true;
}

void Renderer::stop() {
    stopped_ = true;
    cancel();
}

int Renderer::run(int passes) {
    return density_estimator(settings_.estimator).independent_passes ? run_independent(passes)
                                                                     : run_in_order(passes);
}

// Independent passes: the next indices, past any that run_passes() already ran, dealt to
// the workers.
int Renderer::run_independent(int passes) {
    std::vector<std::uint64_t> ran_before;
    for (const auto& g : gpus_)
        ran_before.insert(ran_before.end(), g->pass_indices.begin(), g->pass_indices.end());
    std::sort(ran_before.begin(), ran_before.end());
    std::vector<std::uint64_t> indices;
    for (std::uint64_t i = next_pass_;
         indices.size() < static_cast<std::size_t>(std::max(passes, 0)); ++i)
        if (!std::binary_search(ran_before.begin(), ran_before.end(), i)) indices.push_back(i);
    const int done = run_workers(indices);
    // A cancelled run leaves the indices it did not reach for the next one.
    std::vector<std::uint64_t> ran;
    for (const auto& g : gpus_)
        ran.insert(ran.end(), g->pass_indices.begin(), g->pass_indices.end());
    for (std::uint64_t i : ran) next_pass_ = std::max(next_pass_, i + 1);
    return done;
}

// Passes that depend on each other: in order, on the one worker.
int Renderer::run_in_order(int passes) {
    Gpu& g = *gpus_[0];
    // Runs queue on the GL thread one after another (two callers never interleave); the
    // time counted is this run's own, measured on that thread.
    return g.thread->call([&] {
        const auto start = std::chrono::steady_clock::now();
        g.cancel = false;
        int done = 0;
        for (; done < passes && !g.cancel && !stopped_; ++done) {
            g.run_pass(g.passes);
            // Let a cancel or a film read in between interrupt long runs (the GPU queue is
            // flushed every few passes so that a cancel takes effect quickly).
            if ((done & 7) == 7) glFlush();
        }
        glFinish();
        g.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return done;
    });
}

int Renderer::run_passes(const std::vector<std::uint64_t>& indices) {
    const DensityEstimator& estimator = density_estimator(settings_.estimator);
    if (!estimator.independent_passes)
        throw std::invalid_argument("run_passes: needs estimator " +
                                    independent_estimator_names() + " (" + estimator.title +
                                    "'s passes run in order)");
    std::vector<std::uint64_t> sorted = indices;
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t k = 1; k < sorted.size(); ++k)
        if (sorted[k] == sorted[k - 1])
            throw std::invalid_argument("run_passes: pass " + std::to_string(sorted[k]) +
                                        " is listed twice");
    for (const auto& g : gpus_)
        for (std::uint64_t i : g->pass_indices)
            if (std::binary_search(sorted.begin(), sorted.end(), i))
                throw std::invalid_argument("run_passes: pass " + std::to_string(i) +
                                            " has already been run by this renderer");
    return run_workers(indices);
}

// Each worker takes the next index from a shared counter when its GPU has caught up to one
// pass behind, so a faster device takes more passes. One worker runs on its own thread;
// several each on theirs, at once.
int Renderer::run_workers(const std::vector<std::uint64_t>& indices) {
    std::atomic<std::size_t> next{0};
    auto work = [&](Gpu& g) {
        return g.thread->call([&] {
            const auto start = std::chrono::steady_clock::now();
            g.cancel = false;
            int done = 0;
            GLsync in_flight = nullptr;
            while (!g.cancel && !stopped_) {
                const std::size_t k = next.fetch_add(1);
                if (k >= indices.size()) break;
                const auto submit = std::chrono::steady_clock::now();
                g.run_pass(indices[k]);
                g.pass_indices.push_back(indices[k]);
                ++done;
                // At most two passes queued: the counter then deals by the GPUs' own speed.
                GLsync fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
                const auto wait = std::chrono::steady_clock::now();
                if (in_flight) {
                    glClientWaitSync(in_flight, GL_SYNC_FLUSH_COMMANDS_BIT, ~GLuint64(0));
                    glDeleteSync(in_flight);
                }
                in_flight = fence;
                glFlush();
                const auto waited = std::chrono::steady_clock::now();
                g.submit_seconds += std::chrono::duration<double>(wait - submit).count();
                g.wait_seconds += std::chrono::duration<double>(waited - wait).count();
            }
            if (in_flight) glDeleteSync(in_flight);
            glFinish();
            g.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            return done;
        });
    };
    const auto start = std::chrono::steady_clock::now();
    int done = 0;
    if (gpus_.size() == 1) {
        done = work(*gpus_[0]);
    } else {
        std::vector<std::future<int>> runs;
        for (auto& g : gpus_) runs.push_back(std::async(std::launch::async, work, std::ref(*g)));
        std::exception_ptr failure;
        for (auto& r : runs) {
            try {
                done += r.get();
            } catch (...) {
                if (!failure) failure = std::current_exception();
                cancel();
            }
        }
        if (failure) std::rethrow_exception(failure);
    }
    seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return done;
}

// The viewport's restarts apply to every worker, each on its own GL thread. Independent
// passes: the indices start again from settings.first_pass (a restarted film has run none).
void Renderer::restart_passes() {
    next_pass_ = settings_.first_pass;
    seconds_ = 0.0;
}

void Renderer::reset_film() {
    for (auto& w : gpus_) {
        Gpu& g = *w;
        g.thread->call([&] {
            g.restart_film();
            ++g.film_resets;
        });
    }
    restart_passes();
}

bool Renderer::set_camera(const Camera& camera) {
    validate_camera(camera);
    // The programs were specialized for depth of field (the projection is the Frame's).
    const Gpu& first = *gpus_[0];
    const auto has = [&](const char* define) {
        return std::any_of(first.scene.defines.begin(), first.scene.defines.end(),
                           [&](const auto& d) { return d.first == define; });
    };
    const bool depth_of_field =
        camera.projection == Projection::Perspective && camera.aperture_radius > 0.0f;
    if (!settings_.full_variant && has("HAS_DEPTH_OF_FIELD") != depth_of_field) return false;
    for (auto& w : gpus_) {
        Gpu& g = *w;
        g.thread->call([&] {
            // frame_camera through the worker's MTBVH, one level or two.
            FrameBlock frame = g.scene.frame;
            const float radius = g.two_level ? frame_camera(camera, g.settings, PackedBvh{},
                                                            g.scene.bounds, frame, g.two_level.get())
                                             : frame_camera(camera, g.settings, *g.bvh,
                                                            g.scene.bounds, frame);
            g.scene.frame = frame;
            g.scene.initial_radius = radius;  // a radius per pass scales from it too
            // A camera given here stands still (the viewport's: no motion blur there).
            if (g.scene.motion && g.scene.motion->camera)
                g.scene.motion = g.scene.motion->with_still_camera();
            g.restart_film();
            ++g.camera_updates;
            ++g.film_resets;
        });
    }
    restart_passes();
    scene_hash_ = scene_hash_hex(scene_hash_with_camera(scene_hash_without_camera_, camera));
    return true;
}

bool Renderer::update_tables(const Scene& scene) {
    // Prepared once, on the first worker's thread (its BVH, no run in between); every worker
    // then takes the same tables.
    Gpu& first = *gpus_[0];
    std::optional<PreparedScene> prepared;
    const bool same = first.thread->call([&] {
        prepared.emplace(prepare_scene(scene, first.settings, kLocalSize, nullptr,
                                       first.bvh.get(), flatten_max_triangles_));
        const PreparedScene& p = *prepared;
        const PipelineScene& kept = first.scene;
        return p.geometry_triangles == kept.geometry_triangles &&
               p.material_count == kept.material_count && p.variant == kept.variant &&
               p.defines == kept.defines && p.textures.used == kept.textures.used &&
               !p.environment;
    });
    if (!same) return false;
    const PreparedScene& p = *prepared;
    for (auto& w : gpus_) {
        Gpu& g = *w;
        g.thread->call([&] {
            g.replace_buffer(g.buffers.materials, p.material_records.size() * sizeof(glm::vec4),
                             p.material_records.data(), "materials");
            const EmitterTable& emitters = p.emitters;
            g.replace_buffer(g.buffers.emitter_records,
                             emitters.records.size() * sizeof(emitters.records[0]),
                             emitters.records.data(), "emitters");
            g.scene.emitters = emitters;
            g.scene.frame = p.frame;
            g.scene.initial_radius = p.initial_radius;
            g.restart_film();
            ++g.table_updates;
            ++g.film_resets;
        });
    }
    restart_passes();
    // The farm attributes describe the new scene.
    scene_hash_without_camera_ = scene_hash_without_camera(scene);
    scene_hash_ = scene_hash_hex(scene_hash_with_camera(scene_hash_without_camera_, scene.camera));
    return true;
}

void Renderer::debug_set_photons_emitted(std::uint64_t count) {
    Gpu& g = *gpus_[0];
    g.thread->call([&] {
        const std::uint32_t words[2] = {static_cast<std::uint32_t>(count),
                                        static_cast<std::uint32_t>(count >> 32)};
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, g.buffers.counters);
        glBufferSubData(GL_SHADER_STORAGE_BUFFER, offsetof(Counters, emitted_lo), sizeof(words),
                        words);
    });
}

}  // namespace glslppm
