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
Renderer::Renderer(const Scene& scene, const RenderSettings& settings, const CancelFlag* cancel)
    : settings_(settings), next_pass_(settings.first_pass) {
    const std::vector<int> devices =
        settings.devices.empty() ? std::vector<int>{settings.device} : settings.devices;
    // Flattening instances pays up to a larger size on a GPU than on llvmpipe; with several
    // devices, the smallest bound of theirs.
    flatten_max_triangles_ = kFlattenMaxTrianglesGpu;
    for (int device : devices)
        if (gl::is_software_device(device)) flatten_max_triangles_ = kFlattenMaxTrianglesSoftware;
    PreparedScene prepared =
        prepare_scene(scene, settings, kLocalSize, cancel, nullptr, flatten_max_triangles_);
    if (prepared.two_level) {
        // The same buffers carry the two-level tree (bvh/two_level_bvh.h): the top tree's node
        // count is what the traversal starts from.
        TwoLevelBvh& two = *prepared.two_level;
        PackedBvh& bvh = prepared.bvh;
        bvh.nodes = std::move(two.nodes);
        bvh.links = std::move(two.links);
        bvh.triangles = std::move(two.triangles);
        bvh.normals = std::move(two.normals);
        bvh.uvs = std::move(two.uvs);
        bvh.node_count = two.top_node_count;
        BvhStats& st = bvh.stats;
        st.triangles = two.stats.mesh_triangles;
        st.build_seconds += two.stats.bottom_seconds + two.stats.top_seconds;
        st.bytes_total = two.stats.bytes_total;
        st.bytes_per_triangle =
            st.triangles ? static_cast<double>(st.bytes_total) / static_cast<double>(st.triangles) : 0.0;
    }
    std::vector<glm::vec4> instances;  // two-level instance records, else empty
    if (prepared.two_level) instances = std::move(prepared.two_level->instances);
    scene_hash_without_camera_ = scene_hash_without_camera(scene, cancel);
    scene_hash_ = scene_hash_hex(scene_hash_with_camera(scene_hash_without_camera_, scene.camera));
    try {
        for (std::size_t k = 0; k < devices.size(); ++k) {
            gpus_.push_back(std::make_unique<Gpu>());
            // The last worker takes the BVH (one or two levels); the others copy it.
            Gpu& g = *gpus_.back();
            if (k + 1 == devices.size()) {
                g.bvh = std::move(prepared.bvh);
                g.instances = std::move(instances);
            } else {
                g.bvh = prepared.bvh;
                g.instances = instances;
            }
            g.instancing = prepared.instancing;
            g.instance_count = scene.instances.size();
            set_up(g, devices[k], scene, settings, prepared, cancel);
        }
    } catch (...) {
        for (auto& g : gpus_)
            if (g->thread) g->thread->call([&] { g->release(); });
        throw;
    }
}

// One worker: its context on `device`, the programs, the buffers (g.bvh, g.instances and
// g.instancing already set).
void Renderer::set_up(Gpu& g, int device, const Scene& scene, const RenderSettings& settings,
                      const PreparedScene& prepared, const CancelFlag* cancel) {
    g.setup_cancel = cancel;
    g.settings = settings;
    g.device = device;
    g.bounds = prepared.bounds;
    g.emitters = prepared.emitters;
    g.frame = prepared.frame;
    g.defines = prepared.defines;
    g.variant = prepared.variant;
    g.pixels = prepared.pixels;
    g.photon_threads = prepared.photon_threads;
    g.hash_cells = prepared.hash_cells;
    g.initial_radius = prepared.initial_radius;
    g.warnings = prepared.warnings;
    g.geometry_triangles = prepared.geometry.mesh.triangles.size();
    g.material_count = prepared.geometry.materials.size();
    g.textures_used = prepared.textures.used;
    const TextureUse& use = prepared.textures;
    const EnvironmentMap* environment = prepared.environment.get();

    throw_if_cancelled(cancel);
    g.thread = std::make_unique<gl::GlThread>(g.device);
    g.thread->call([&] {
        try {
            const auto compile_start = std::chrono::steady_clock::now();
            gl::ProgramCache& cache = g.thread->context().programs();
            auto program = [&](const char* file, const char* phase) -> const gl::ComputeProgram* {
                throw_if_cancelled(cancel);  // a compile on llvmpipe takes up to a second
                gl::Defines d = g.defines;
                if (phase) d.push_back({phase, "1"});
                return &cache.get(file, d);
            };
            const bool exact = settings.hash == HashMode::Exact;
            g.eye = program("eye_trace.comp", nullptr);
            g.photon = program("photon_trace.comp", nullptr);
            g.hash_clear = program("hash_photons.comp", "PHASE_CLEAR");
            g.hash_a = program("hash_photons.comp", exact ? "PHASE_COUNT" : "PHASE_INSERT");
            g.hash_b = program("hash_photons.comp", exact ? "PHASE_SCATTER" : "PHASE_WINNER");
            if (exact) {
                g.scan[0] = program("prefix_sum.comp", "PHASE_BLOCKS");
                g.scan[1] = program("prefix_sum.comp", "PHASE_BLOCK_SUMS");
                g.scan[2] = program("prefix_sum.comp", "PHASE_ADD");
            }
            g.gather = program("gather.comp", nullptr);
            g.end_pass = program("end_pass.comp", nullptr);
            g.restart = program("restart_film.comp", nullptr);
            g.resolve = program("resolve_film.comp", nullptr);
            g.radius_reduce = program("radius_stats.comp", nullptr);
            for (const gl::ComputeProgram* p : {g.eye, g.photon, g.hash_clear, g.hash_a, g.hash_b, g.scan[0],
                                                g.scan[1], g.scan[2], g.gather, g.end_pass,
                                                g.restart, g.resolve}) {
                if (p) ++(p->reused() ? g.programs_reused : g.programs_compiled);
            }
            g.compile_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                                              compile_start).count();
            // The traversal's node count, in every program that traces rays.
            for (const gl::ComputeProgram* p : {g.eye, g.photon}) {
                p->use();
                glUniform1ui(p->uniform("bvh_node_count"), g.bvh.node_count);
            }

            throw_if_cancelled(cancel);
            if (settings.profile) {
                glGenQueries(5, g.queries);
                gl::count_gl_objects(gl::GlObject::Query, 5);
            }
            glGenBuffers(1, &g.ubo);
            gl::count_gl_objects(gl::GlObject::Buffer, 1);
            glBindBuffer(GL_UNIFORM_BUFFER, g.ubo);
            glBufferData(GL_UNIFORM_BUFFER, sizeof(FrameBlock), &g.frame, GL_DYNAMIC_DRAW);
            glBindBufferBase(GL_UNIFORM_BUFFER, BINDING_FRAME, g.ubo);

            auto bytes = [](const auto& v) { return v.size() * sizeof(v[0]); };
            g.make_buffer(BINDING_BVH_NODES, bytes(g.bvh.nodes), g.bvh.nodes.data(), "BVH nodes");
            g.make_buffer(BINDING_BVH_LINKS, bytes(g.bvh.links), g.bvh.links.data(), "BVH links");
            g.make_buffer(BINDING_TRIANGLES, bytes(g.bvh.triangles), g.bvh.triangles.data(), "triangles");
            if (!g.instances.empty())
                g.make_buffer(BINDING_INSTANCES, bytes(g.instances), g.instances.data(), "instances");
            if (!g.bvh.normals.empty())
                g.make_buffer(BINDING_NORMALS, bytes(g.bvh.normals), g.bvh.normals.data(), "normals");
            else if (settings.full_variant)
                g.make_buffer(BINDING_NORMALS, 16, nullptr, "normals");
            if (!g.bvh.uvs.empty())
                g.make_buffer(BINDING_UVS, bytes(g.bvh.uvs), g.bvh.uvs.data(), "uvs");
            else if (settings.full_variant)
                g.make_buffer(BINDING_UVS, 16, nullptr, "uvs");
            if (use.materials || use.environment || settings.full_variant) {
                GLint max_size = 0, max_layers = 0;
                glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
                glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &max_layers);
                if (settings.max_texture_size > 0)
                    max_size = std::min(max_size, settings.max_texture_size);
                const TextureAtlas atlas = pack_textures(scene.textures, use.used, max_size,
                                                         max_layers);
                for (const std::string& w : atlas.warnings) g.warnings.push_back(w);
                const std::vector<glm::ivec4> records = atlas.records();
                g.make_buffer(BINDING_TEXTURE_INFO, bytes(records), records.data(), "texture records");
                g.upload_atlas(atlas);
            }
            if (environment) {
                g.make_buffer(BINDING_ENVIRONMENT_CDF, bytes(environment->cdf), environment->cdf.data(),
                              "environment distribution");
            } else if (settings.full_variant) {
                g.make_buffer(BINDING_ENVIRONMENT_CDF, 16, nullptr, "environment distribution");
            }
            g.emitter_records = g.make_buffer(BINDING_EMITTERS, bytes(g.emitters.records),
                                              g.emitters.records.data(), "lights");
            g.materials = g.make_buffer(BINDING_MATERIALS, bytes(prepared.material_records),
                                        prepared.material_records.data(), "materials");
            g.counters = g.make_buffer(BINDING_COUNTERS, sizeof(Counters), nullptr, "counters");

            const std::size_t px = g.pixels, ph = g.photon_threads;
            const std::size_t point_vec4s = prepared.microfacet ? 4 : 3;
            g.require_fits(px * point_vec4s * 16, "visible points", true);
            g.require_fits(ph * 3 * 16, "photons");
            g.require_fits(std::size_t(g.hash_cells) * 16, "hash cells");
            // Visible points, pixel statistics, direct light, film.
            g.gpu_bytes_per_pixel = (point_vec4s + 2 + 2 + 1) * 16;
            g.make_buffer(BINDING_VISIBLE_POINTS, px * point_vec4s * 16, nullptr, "visible points");
            // Their first contents: restart_film() below, as at every restart.
            g.pixel_stats = g.make_buffer(BINDING_PIXEL_STATS, px * 2 * 16, nullptr,
                                          "pixel statistics");
            g.direct_light = g.make_buffer(BINDING_DIRECT_LIGHT, px * 2 * 16, nullptr,
                                           "direct light");
            g.photon_paths = g.make_buffer(BINDING_PHOTON_PATHS, ph * 3 * 16, nullptr,
                                           "photon paths");
            // PPPM: the photon steps of a pass are stored side by side and hashed and
            // gathered together, as many as fit in a storage buffer of at most 1 GiB; SPPM
            // stores one step. Each step's slot is rounded up to 16 photons (offset
            // alignment); the padding stays zero, "not stored".
            g.photon_slot = settings.estimator == Estimator::Pppm ? (ph + 15) / 16 * 16 : ph;
            if (settings.estimator == Estimator::Pppm) {
                GLint64 largest = 0;
                glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &largest);
                const std::size_t cap = std::min<std::size_t>(
                    largest > 0 ? static_cast<std::size_t>(largest) : std::size_t(1) << 30,
                    std::size_t(1) << 30);
                g.steps_per_gather = static_cast<std::uint32_t>(std::clamp<std::size_t>(
                    cap / (g.photon_slot * 3 * 16), 1, static_cast<std::size_t>(settings.max_bounces)));
            }
            const std::size_t stored = std::size_t(g.photon_slot) * g.steps_per_gather;
            g.require_fits(stored * 3 * 16, "photons");
            g.photons = g.make_buffer(BINDING_PHOTONS, stored * 3 * 16, nullptr, "photons");
            const GLuint zero[4] = {0, 0, 0, 0};
            glClearBufferData(GL_SHADER_STORAGE_BUFFER, GL_RGBA32UI, GL_RGBA_INTEGER,
                              GL_UNSIGNED_INT, zero);
            if (settings.rng == RngKind::Paper) {
                const std::vector<glm::vec4> seeds = paper_rng_seeds(px + ph, settings.seed);
                g.make_buffer(BINDING_RNG_STATES, bytes(seeds), seeds.data(), "generator states");
            }
            g.hash = g.make_buffer(BINDING_HASH_CELLS, std::size_t(g.hash_cells) * 16, nullptr, "hash cells");
            const std::size_t sorted = exact ? stored + g.hash_cells / 1024 : 1;
            g.make_buffer(BINDING_HASH_SORTED, sorted * 4, nullptr, "sorted photons");
            g.gpu_bytes_per_photon =
                double(ph * 3 * 16 + stored * 3 * 16 + std::size_t(g.hash_cells) * 16 +
                       (exact ? sorted * 4 : 0) +
                       (settings.rng == RngKind::Paper ? ph * 16 : 0)) /
                double(std::max<std::size_t>(ph, 1));
            g.film = g.make_buffer(BINDING_FILM, px * 16, nullptr, "film");
            g.pass_layout = prepared.pass_layout;
            if (g.pass_layout.stride > 0) {
                const std::size_t pass_bytes = px * std::size_t(g.pass_layout.stride) * 16;
                g.require_fits(pass_bytes, "render passes", true);
                g.pass_films = g.make_buffer(BINDING_PASS_FILMS, pass_bytes, nullptr,
                                             "render passes");
                g.gpu_bytes_per_pixel += std::size_t(g.pass_layout.stride) * 16;
            }
            g.radius_stats = g.make_buffer(BINDING_RADIUS_STATS, kRadiusStatsThreads * 8, nullptr,
                                           "radius statistics");
            g.restart_film();
            g.setup_cancel = nullptr;
            glFinish();
        } catch (...) {
            g.release();
            throw;
        }
    });
}

Renderer::~Renderer() {
    for (auto& g : gpus_) g->cancel = true;  // runs in progress stop after their current pass
    for (auto& g : gpus_)
        if (g->thread) g->thread->call([&] { g->release(); });
}

void Renderer::cancel() {
    for (auto& g : gpus_) g->cancel = true;
}

int Renderer::run(int passes) {
    if (settings_.estimator == Estimator::Pppm) {
        // The next indices, past any that run_passes() already ran.
        std::vector<std::uint64_t> ran_before;
        for (const auto& g : gpus_)
            ran_before.insert(ran_before.end(), g->pass_indices.begin(), g->pass_indices.end());
        std::sort(ran_before.begin(), ran_before.end());
        std::vector<std::uint64_t> indices;
        for (std::uint64_t i = next_pass_; indices.size() < static_cast<std::size_t>(std::max(passes, 0)); ++i)
            if (!std::binary_search(ran_before.begin(), ran_before.end(), i)) indices.push_back(i);
        const int done = run_workers(indices);
        // A cancelled run leaves the indices it did not reach for the next one.
        std::vector<std::uint64_t> ran;
        for (const auto& g : gpus_) ran.insert(ran.end(), g->pass_indices.begin(), g->pass_indices.end());
        for (std::uint64_t i : ran) next_pass_ = std::max(next_pass_, i + 1);
        return done;
    }
    Gpu& g = *gpus_[0];
    // Runs queue on the GL thread one after another (two callers never interleave); the
    // time counted is this run's own, measured on that thread.
    return g.thread->call([&] {
        const auto start = std::chrono::steady_clock::now();
        g.cancel = false;
        int done = 0;
        for (; done < passes && !g.cancel; ++done) {
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
    if (settings_.estimator != Estimator::Pppm)
        throw std::invalid_argument("run_passes: needs estimator pppm (SPPM's passes run in order)");
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
            while (!g.cancel) {
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

// The viewport's restarts apply to every worker, each on its own GL thread. PPPM: the pass
// indices start again from settings.first_pass (a restarted film has run none).
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
    // The programs were specialized for the projection and for depth of field.
    const Gpu& first = *gpus_[0];
    const auto has = [&](const char* define) {
        return std::any_of(first.defines.begin(), first.defines.end(),
                           [&](const auto& d) { return d.first == define; });
    };
    const bool orthographic = camera.projection == Projection::Orthographic;
    const bool depth_of_field = !orthographic && camera.aperture_radius > 0.0f;
    if (!settings_.full_variant &&
        (has("HAS_ORTHOGRAPHIC") != orthographic || has("HAS_DEPTH_OF_FIELD") != depth_of_field))
        return false;
    // frame_camera through a worker's own MTBVH. On the two-level path its buffers hold the
    // TwoLevelBvh's arrays (the constructor moved them in): they are lent back to one for
    // the call, since walking them as a one-level tree measures the wrong distances.
    auto frame_worker_camera = [&](Gpu& g, FrameBlock& frame) {
        if (g.instances.empty()) return frame_camera(camera, g.settings, g.bvh, g.bounds, frame);
        TwoLevelBvh two;
        two.top_node_count = g.bvh.node_count;
        auto lend = [&] {
            two.nodes.swap(g.bvh.nodes);
            two.links.swap(g.bvh.links);
            two.triangles.swap(g.bvh.triangles);
            two.normals.swap(g.bvh.normals);
            two.uvs.swap(g.bvh.uvs);
            two.instances.swap(g.instances);
        };
        lend();
        struct GiveBack {
            decltype(lend)& back;
            ~GiveBack() { back(); }
        } give_back{lend};
        return frame_camera(camera, g.settings, PackedBvh{}, g.bounds, frame, &two);
    };
    for (auto& w : gpus_) {
        Gpu& g = *w;
        g.thread->call([&] {
            FrameBlock frame = g.frame;
            const float radius = frame_worker_camera(g, frame);
            g.frame = frame;
            g.initial_radius = radius;  // PPPM's pass radii scale from it too
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
        prepared.emplace(prepare_scene(scene, first.settings, kLocalSize, nullptr, &first.bvh,
                                       flatten_max_triangles_));
        const PreparedScene& p = *prepared;
        return p.geometry.mesh.triangles.size() == first.geometry_triangles &&
               p.geometry.materials.size() == first.material_count && p.variant == first.variant &&
               p.defines == first.defines && p.textures.used == first.textures_used &&
               !p.environment;
    });
    if (!same) return false;
    const PreparedScene& p = *prepared;
    for (auto& w : gpus_) {
        Gpu& g = *w;
        g.thread->call([&] {
            g.replace_buffer(g.materials, p.material_records.size() * sizeof(glm::vec4),
                             p.material_records.data(), "materials");
            g.emitters = p.emitters;
            g.replace_buffer(g.emitter_records,
                             g.emitters.records.size() * sizeof(g.emitters.records[0]),
                             g.emitters.records.data(), "lights");
            g.frame = p.frame;
            g.initial_radius = p.initial_radius;
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
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, g.counters);
        glBufferSubData(GL_SHADER_STORAGE_BUFFER, offsetof(Counters, emitted_lo), sizeof(words),
                        words);
    });
}

std::vector<float> Renderer::film() {
    if (gpus_.size() == 1) {
        Gpu& g = *gpus_[0];
        return g.thread->call([&] { return g.resolve_film(); });
    }
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
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, g.photons);
        glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(out.size() * 4),
                           out.data());
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
