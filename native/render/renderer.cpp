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
#include <stdexcept>

#include <epoxy/gl.h>

#include "gl/object_counts.h"
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
#include "scene/scene_validation.h"

namespace glslppm {
Renderer::Renderer(const Scene& scene, const RenderSettings& settings, const CancelFlag* cancel)
    : settings_(settings), gpu_(std::make_unique<Gpu>()) {
    Gpu& g = *gpu_;
    g.settings = settings;
    g.setup_cancel = cancel;

    PreparedScene prepared = prepare_scene(scene, settings, kLocalSize, cancel);
    g.bvh = std::move(prepared.bvh);
    g.instancing = prepared.instancing;
    g.instance_count = scene.instances.size();
    if (prepared.two_level) {
        // The same buffers carry the two-level tree (bvh/two_level_bvh.h): the top tree's node
        // count is what the traversal starts from.
        TwoLevelBvh& two = *prepared.two_level;
        g.bvh.nodes = std::move(two.nodes);
        g.bvh.links = std::move(two.links);
        g.bvh.triangles = std::move(two.triangles);
        g.bvh.normals = std::move(two.normals);
        g.bvh.uvs = std::move(two.uvs);
        g.bvh.node_count = two.top_node_count;
        g.instances = std::move(two.instances);
        BvhStats& st = g.bvh.stats;
        st.triangles = two.stats.mesh_triangles;
        st.build_seconds += two.stats.bottom_seconds + two.stats.top_seconds;
        st.bytes_total = two.stats.bytes_total;
        st.bytes_per_triangle =
            st.triangles ? static_cast<double>(st.bytes_total) / static_cast<double>(st.triangles) : 0.0;
    }
    g.bounds = prepared.bounds;
    g.emitters = std::move(prepared.emitters);
    g.frame = prepared.frame;
    g.defines = std::move(prepared.defines);
    g.variant = std::move(prepared.variant);
    g.pixels = prepared.pixels;
    g.photon_threads = prepared.photon_threads;
    g.hash_cells = prepared.hash_cells;
    g.initial_radius = prepared.initial_radius;
    g.warnings = std::move(prepared.warnings);
    g.geometry_triangles = prepared.geometry.mesh.triangles.size();
    g.material_count = prepared.geometry.materials.size();
    g.textures_used = prepared.textures.used;
    const SceneGeometry& geometry = prepared.geometry;
    const TextureUse& use = prepared.textures;
    const EnvironmentMap* environment = prepared.environment.get();
    const float radius = prepared.initial_radius;

    throw_if_cancelled(cancel);
    g.thread = std::make_unique<gl::GlThread>(settings.device);
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
            g.hash_a = program("hash_photons.comp", exact ? "PHASE_COUNT" : "PHASE_INSERT");
            g.hash_b = program("hash_photons.comp", exact ? "PHASE_SCATTER" : "PHASE_WINNER");
            if (exact) {
                g.scan[0] = program("prefix_sum.comp", "PHASE_BLOCKS");
                g.scan[1] = program("prefix_sum.comp", "PHASE_BLOCK_SUMS");
                g.scan[2] = program("prefix_sum.comp", "PHASE_ADD");
            }
            g.gather = program("gather.comp", nullptr);
            g.end_pass = program("end_pass.comp", nullptr);
            g.resolve = program("resolve_film.comp", nullptr);
            g.radius_reduce = program("radius_stats.comp", nullptr);
            for (const gl::ComputeProgram* p : {g.eye, g.photon, g.hash_a, g.hash_b, g.scan[0],
                                                g.scan[1], g.scan[2], g.gather, g.end_pass,
                                                g.resolve}) {
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
            g.pixel_stats = g.make_buffer(BINDING_PIXEL_STATS, px * 2 * 16, nullptr,
                                          "pixel statistics");
            g.direct_light = g.make_buffer(BINDING_DIRECT_LIGHT, px * 2 * 16, nullptr,
                                           "direct light");
            g.photon_paths = g.make_buffer(BINDING_PHOTON_PATHS, ph * 3 * 16, nullptr,
                                           "photon paths");
            const std::vector<glm::vec4> no_photons(ph * 3, glm::vec4(0.0f));
            g.photons = g.make_buffer(BINDING_PHOTONS, bytes(no_photons), no_photons.data(),
                                      "photons");
            if (settings.rng == RngKind::Paper) {
                const std::vector<glm::vec4> seeds = paper_rng_seeds(px + ph, settings.seed);
                g.make_buffer(BINDING_RNG_STATES, bytes(seeds), seeds.data(), "generator states");
            }
            g.hash = g.make_buffer(BINDING_HASH_CELLS, std::size_t(g.hash_cells) * 16, nullptr, "hash cells");
            const std::size_t sorted = exact ? ph + g.hash_cells / 1024 : 1;
            g.make_buffer(BINDING_HASH_SORTED, sorted * 4, nullptr, "sorted photons");
            g.film = g.make_buffer(BINDING_FILM, px * 16, nullptr, "film");
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
    if (!gpu_ || !gpu_->thread) return;
    gpu_->cancel = true;  // a run in progress stops after its current pass
    gpu_->thread->call([this] { gpu_->release(); });
}

void Renderer::cancel() { gpu_->cancel = true; }

int Renderer::run(int passes) {
    Gpu& g = *gpu_;
    // Runs queue on the GL thread one after another (two callers never interleave); the
    // time counted is this run's own, measured on that thread.
    return g.thread->call([&] {
        const auto start = std::chrono::steady_clock::now();
        g.cancel = false;
        int done = 0;
        for (; done < passes && !g.cancel; ++done) {
            g.run_pass();
            // Let a cancel or a film read in between interrupt long runs (the GPU queue is
            // flushed every few passes so that a cancel takes effect quickly).
            if ((done & 7) == 7) glFlush();
        }
        glFinish();
        g.seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return done;
    });
}

void Renderer::reset_film() {
    Gpu& g = *gpu_;
    g.thread->call([&] {
        g.restart_film();
        ++g.film_resets;
    });
}

bool Renderer::set_camera(const Camera& camera) {
    Gpu& g = *gpu_;
    validate_camera(camera);
    // The programs were specialized for the projection and for depth of field.
    const auto has = [&](const char* define) {
        return std::any_of(g.defines.begin(), g.defines.end(),
                           [&](const auto& d) { return d.first == define; });
    };
    const bool orthographic = camera.projection == Projection::Orthographic;
    const bool depth_of_field = !orthographic && camera.aperture_radius > 0.0f;
    if (!g.settings.full_variant &&
        (has("HAS_ORTHOGRAPHIC") != orthographic || has("HAS_DEPTH_OF_FIELD") != depth_of_field))
        return false;
    return g.thread->call([&] {
        FrameBlock frame = g.frame;
        const float radius = frame_camera(camera, g.settings, g.bvh, g.bounds, frame);
        g.frame = frame;
        g.initial_radius = radius;
        g.restart_film();
        ++g.camera_updates;
        ++g.film_resets;
        return true;
    });
}

bool Renderer::update_tables(const Scene& scene) {
    Gpu& g = *gpu_;
    return g.thread->call([&] {
        PreparedScene p = prepare_scene(scene, g.settings, kLocalSize, nullptr, &g.bvh);
        if (p.geometry.mesh.triangles.size() != g.geometry_triangles ||
            p.geometry.materials.size() != g.material_count ||
            p.variant != g.variant || p.defines != g.defines || p.textures.used != g.textures_used ||
            p.environment)
            return false;
        g.replace_buffer(g.materials, p.material_records.size() * sizeof(glm::vec4),
                         p.material_records.data(), "materials");
        g.emitters = std::move(p.emitters);
        g.replace_buffer(g.emitter_records, g.emitters.records.size() * sizeof(g.emitters.records[0]),
                         g.emitters.records.data(), "lights");
        g.frame = p.frame;
        g.initial_radius = p.initial_radius;
        g.restart_film();
        ++g.table_updates;
        ++g.film_resets;
        return true;
    });
}

void Renderer::debug_set_photons_emitted(std::uint64_t count) {
    Gpu& g = *gpu_;
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
    Gpu& g = *gpu_;
    std::vector<float> out(std::size_t(g.pixels) * 4, 0.0f);
    g.thread->call([&] {
        const Counters c = g.read_counters();
        const std::uint64_t emitted = Gpu::total(c.emitted_lo, c.emitted_hi);
        g.frame.inv_passes = g.passes ? 1.0f / static_cast<float>(g.passes) : 0.0f;
        g.frame.inv_photons_emitted = emitted ? static_cast<float>(1.0 / static_cast<double>(emitted)) : 0.0f;
        g.upload_frame();
        g.dispatch(*g.resolve, g.pixels);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, g.film);
        glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(out.size() * 4),
                           out.data());
    });
    return out;
}

std::vector<float> Renderer::photons() {
    Gpu& g = *gpu_;
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
    Gpu& g = *gpu_;
    RenderStats s;
    std::vector<glm::vec2> radius_stats(kRadiusStatsThreads);
    Counters c{};
    g.thread->call([&] {
        // One consistent snapshot: runs change these on this thread only.
        s.passes = g.passes;
        s.seconds = g.seconds;
        c = g.read_counters();
        // The radii reduced on the GPU: a few KiB read back, not every pixel's statistics.
        g.radius_reduce->use();
        glDispatchCompute(1, 1, 1);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, g.radius_stats);
        glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0,
                           static_cast<GLsizeiptr>(radius_stats.size() * sizeof(glm::vec2)),
                           radius_stats.data());
    });
    double sum = 0.0, largest = 0.0;
    for (const glm::vec2& t : radius_stats) {
        sum += t.x;
        largest = std::max(largest, static_cast<double>(t.y));
    }
    s.photons_emitted = Gpu::total(c.emitted_lo, c.emitted_hi);
    s.rays = Gpu::total(c.rays_lo, c.rays_hi);
    s.photons_per_second = g.seconds > 0 ? static_cast<double>(s.photons_emitted) / g.seconds : 0;
    s.rays_per_second = g.seconds > 0 ? static_cast<double>(s.rays) / g.seconds : 0;
    s.mean_radius = g.pixels ? sum / g.pixels : 0.0;
    s.max_radius = largest;
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
    s.gpu_bytes = g.gpu_bytes;
    s.gpu_bytes_per_pixel = g.gpu_bytes_per_pixel;
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
