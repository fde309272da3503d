// Renderer::set_up: one worker's GL thread and context, its programs and its buffers
// (the rest of the Renderer is in renderer.cpp; results read back in renderer_readback.cpp).
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
            if (prepared.vertex_colors)  // empty in the full variant without colours
                g.make_buffer(BINDING_VERTEX_COLORS, std::max<std::size_t>(bytes(g.bvh.colors), 16),
                              g.bvh.colors.empty() ? nullptr : g.bvh.colors.data(),
                              "vertex colours");
            if (use.materials || use.environment || settings.full_variant) {
                GLint max_size = 0, max_layers = 0;
                glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
                glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &max_layers);
                if (settings.max_texture_size > 0)
                    max_size = std::min(max_size, settings.max_texture_size);
                const TextureAtlas atlas = pack_textures(scene.textures, use.used, max_size,
                                                         max_layers);
                for (const std::string& w : atlas.warnings) g.warnings.push_back(w);
                const std::vector<GpuTexture> records = atlas.records();
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
            const std::size_t point_vec4s = kVisiblePointVec4;
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
                    cap / (g.photon_slot * 3 * 16), 1, static_cast<std::size_t>(settings.max_bounces) + 1));
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

}  // namespace glslppm
