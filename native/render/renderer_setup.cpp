// Renderer::set_up: one worker's GL thread and context, its programs and its buffers
// (the rest of the Renderer is in renderer.cpp; results read back in renderer_readback.cpp).
#include <epoxy/gl.h>

#include <algorithm>
#include <chrono>

#include "gl/object_counts.h"
#include "render/pipeline.h"
#include "render/rng_seed.h"

namespace glslppm {
namespace {

template <class T>
std::size_t bytes(const std::vector<T>& v) {
    return v.size() * sizeof(T);
}

// The stage programs of the prepared variant, from the thread's program cache.
void compile_programs(gl::ProgramCache& cache, const gl::Defines& defines, HashMode hash,
                      bool light_tracing, const CancelFlag* cancel, StagePrograms& s) {
    const auto compile_start = std::chrono::steady_clock::now();
    auto program = [&](const char* file, const char* phase) -> const gl::ComputeProgram* {
        throw_if_cancelled(cancel);  // a compile on llvmpipe takes up to a second
        gl::Defines d = defines;
        if (phase) d.push_back({phase, "1"});
        return &cache.get(file, d);
    };
    const bool exact = hash == HashMode::Exact;
    s.eye = program("eye_trace.comp", nullptr);
    s.photon = program("photon_trace.comp", nullptr);
    s.hash_clear = program("hash_photons.comp", "PHASE_CLEAR");
    s.hash_a = program("hash_photons.comp", exact ? "PHASE_COUNT" : "PHASE_INSERT");
    s.hash_b = program("hash_photons.comp", exact ? "PHASE_SCATTER" : "PHASE_WINNER");
    if (exact) {
        s.scan[0] = program("prefix_sum.comp", "PHASE_BLOCKS");
        s.scan[1] = program("prefix_sum.comp", "PHASE_BLOCK_SUMS");
        s.scan[2] = program("prefix_sum.comp", "PHASE_ADD");
    }
    s.gather = program("gather.comp", nullptr);
    s.end_pass = program("end_pass.comp", nullptr);
    s.restart = program("restart_film.comp", nullptr);
    s.resolve = program("resolve_film.comp", nullptr);
    s.radius_reduce = program("radius_stats.comp", nullptr);
    if (light_tracing) s.light_splats = program("light_splats.comp", nullptr);
    for (const gl::ComputeProgram* p :
         {s.eye, s.photon, s.hash_clear, s.hash_a, s.hash_b, s.scan[0], s.scan[1], s.scan[2],
          s.gather, s.end_pass, s.restart, s.resolve, s.light_splats}) {
        if (p) ++(p->reused() ? s.reused : s.compiled);
    }
    s.compile_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - compile_start).count();
}

// The traced MTBVH's arrays (one level or two: the same fields) and, for two levels, the
// instance records.
template <class Bvh>
void upload_bvh(Renderer::Gpu& g, const Bvh& bvh, const std::vector<glm::vec4>* instances,
                bool vertex_colors) {
    const bool full = g.settings.full_variant;
    g.make_buffer(BINDING_BVH_NODES, bytes(bvh.nodes), bvh.nodes.data(), "BVH nodes");
    g.make_buffer(BINDING_BVH_LINKS, bytes(bvh.links), bvh.links.data(), "BVH links");
    g.make_buffer(BINDING_TRIANGLES, bytes(bvh.triangles), bvh.triangles.data(), "triangles");
    if (instances && !instances->empty())
        g.make_buffer(BINDING_INSTANCES, bytes(*instances), instances->data(), "instances");
    if (!bvh.normals.empty())
        g.make_buffer(BINDING_NORMALS, bytes(bvh.normals), bvh.normals.data(), "normals");
    else if (full)
        g.make_buffer(BINDING_NORMALS, 16, nullptr, "normals");
    if (!bvh.uvs.empty())
        g.make_buffer(BINDING_UVS, bytes(bvh.uvs), bvh.uvs.data(), "uvs");
    else if (full)
        g.make_buffer(BINDING_UVS, 16, nullptr, "uvs");
    if (vertex_colors)  // empty in the full variant without colours
        g.make_buffer(BINDING_VERTEX_COLORS, std::max<std::size_t>(bytes(bvh.colors), 16),
                      bvh.colors.empty() ? nullptr : bvh.colors.data(), "vertex colours");
}

// The scene's buffers: the MTBVH, the images, the environment's distribution, the emitter
// and material tables, and the counters.
void upload_scene(Renderer::Gpu& g, const Scene& scene, const PreparedScene& prepared) {
    const RenderSettings& settings = g.settings;
    if (g.two_level)
        upload_bvh(g, *g.two_level, &g.two_level->instances, prepared.vertex_colors);
    else
        upload_bvh(g, *g.bvh, nullptr, prepared.vertex_colors);
    const TextureUse& use = prepared.textures;
    if (use.materials || use.environment || settings.full_variant) {
        GLint max_size = 0, max_layers = 0;
        glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
        glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &max_layers);
        if (settings.max_texture_size > 0) max_size = std::min(max_size, settings.max_texture_size);
        const TextureAtlas atlas = pack_textures(scene.textures, use.used, max_size, max_layers);
        for (const std::string& w : atlas.warnings) g.scene.warnings.push_back(w);
        const std::vector<GpuTexture> records = atlas.records();
        g.make_buffer(BINDING_TEXTURE_INFO, bytes(records), records.data(), "texture records");
        g.upload_atlas(atlas);
    }
    if (const EnvironmentMap* environment = prepared.environment.get()) {
        g.make_buffer(BINDING_ENVIRONMENT_CDF, bytes(environment->cdf), environment->cdf.data(),
                      "environment distribution");
    } else if (settings.full_variant) {
        g.make_buffer(BINDING_ENVIRONMENT_CDF, 16, nullptr, "environment distribution");
    }
    const EmitterTable& emitters = g.scene.emitters;
    g.buffers.emitter_records =
        g.make_buffer(BINDING_EMITTERS, bytes(emitters.records), emitters.records.data(), "lights");
    g.buffers.materials = g.make_buffer(BINDING_MATERIALS, bytes(prepared.material_records),
                                        prepared.material_records.data(), "materials");
    g.buffers.counters = g.make_buffer(BINDING_COUNTERS, sizeof(Counters), nullptr, "counters");
}

// PPPM: the photon steps of a pass are stored side by side and hashed and gathered
// together, as many as fit in a storage buffer of at most 1 GiB; SPPM stores one step. Each
// step's slot is rounded up to 16 photons (offset alignment); the padding stays zero, "not
// stored".
void plan_photon_slots(Renderer::Gpu& g) {
    const std::size_t ph = g.scene.photon_threads;
    const bool pppm = g.settings.estimator == Estimator::Pppm;
    g.photon_slot =
        pppm ? static_cast<std::uint32_t>((ph + 15) / 16 * 16) : static_cast<std::uint32_t>(ph);
    if (!pppm) return;
    GLint64 largest = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &largest);
    const std::size_t cap = std::min<std::size_t>(
        largest > 0 ? static_cast<std::size_t>(largest) : std::size_t(1) << 30, std::size_t(1)
                                                                                    << 30);
    g.steps_per_gather = static_cast<std::uint32_t>(std::clamp<std::size_t>(
        cap / (g.photon_slot * kPhotonBytes), 1, static_cast<std::size_t>(g.settings.max_bounces) + 1));
}

// The passes' state: per pixel (visible points, statistics, direct light, film, render
// passes) and per photon (paths, stored photons, hash cells, generator states).
void allocate_pass_state(Renderer::Gpu& g, const PreparedScene& prepared) {
    const RenderSettings& settings = g.settings;
    PipelineBuffers& b = g.buffers;
    const bool exact = settings.hash == HashMode::Exact;
    const std::size_t px = g.scene.pixels, ph = g.scene.photon_threads;
    const std::size_t hash_cells = g.scene.hash_cells;
    const std::size_t point_vec4s = kVisiblePointVec4;
    g.require_fits(px * point_vec4s * 16, "visible points", true);
    g.require_fits(ph * kPhotonPathBytes, "photon paths");
    g.require_fits(hash_cells * 16, "hash cells");
    // Visible points, pixel statistics, direct light, film.
    b.bytes_per_pixel = (point_vec4s + 2 + 2 + 1) * 16;
    g.make_buffer(BINDING_VISIBLE_POINTS, px * point_vec4s * 16, nullptr, "visible points");
    // Their first contents: restart_film(), as at every restart.
    b.pixel_stats = g.make_buffer(BINDING_PIXEL_STATS, px * 2 * 16, nullptr, "pixel statistics");
    b.direct_light = g.make_buffer(BINDING_DIRECT_LIGHT, px * 2 * 16, nullptr, "direct light");
    b.photon_paths = g.make_buffer(BINDING_PHOTON_PATHS, ph * kPhotonPathBytes, nullptr, "photon paths");
    plan_photon_slots(g);
    const std::size_t stored = std::size_t(g.photon_slot) * g.steps_per_gather;
    g.require_fits(stored * kPhotonBytes, "photons");
    b.photons = g.make_buffer(BINDING_PHOTONS, stored * kPhotonBytes, nullptr, "photons");
    const GLuint zero[4] = {0, 0, 0, 0};
    glClearBufferData(GL_SHADER_STORAGE_BUFFER, GL_RGBA32UI, GL_RGBA_INTEGER, GL_UNSIGNED_INT,
                      zero);
    if (settings.rng == RngKind::Paper) {
        const std::vector<glm::vec4> seeds = paper_rng_seeds(px + ph, settings.seed);
        g.make_buffer(BINDING_RNG_STATES, bytes(seeds), seeds.data(), "generator states");
    }
    b.hash = g.make_buffer(BINDING_HASH_CELLS, hash_cells * 16, nullptr, "hash cells");
    const std::size_t sorted = exact ? stored + hash_cells / 1024 : 1;
    g.make_buffer(BINDING_HASH_SORTED, sorted * 4, nullptr, "sorted photons");
    b.bytes_per_photon =
        double(ph * kPhotonPathBytes + stored * kPhotonBytes + hash_cells * 16 + (exact ? sorted * 4 : 0) +
               (settings.rng == RngKind::Paper ? ph * 16 : 0)) /
        double(std::max<std::size_t>(ph, 1));
    b.film = g.make_buffer(BINDING_FILM, px * 16, nullptr, "film");
    const PassLayout& layout = g.scene.pass_layout;
    if (layout.stride > 0) {
        const std::size_t pass_bytes = px * std::size_t(layout.stride) * 16;
        g.require_fits(pass_bytes, "render passes", true);
        b.pass_films = g.make_buffer(BINDING_PASS_FILMS, pass_bytes, nullptr, "render passes");
        b.bytes_per_pixel += std::size_t(layout.stride) * 16;
    }
    b.radius_stats =
        g.make_buffer(BINDING_RADIUS_STATS, kRadiusStatsThreads * 8, nullptr, "radius statistics");
    if (g.scene.light_tracing) {
        // kLightSplatBytes a pixel (common/light_splats.glsl); zeroed by restart_film().
        const std::size_t splat_bytes = px * kLightSplatBytes;
        g.require_fits(splat_bytes, "light tracing's splats", true);
        b.light_splats = g.make_buffer(BINDING_LIGHT_SPLATS, splat_bytes, nullptr, "light splats");
        b.bytes_per_pixel += kLightSplatBytes;
    }
}

}  // namespace

// One worker: its context on `device`, the programs, the buffers (g.bvh or g.two_level
// already set).
void Renderer::set_up(Gpu& g, int device, const Scene& scene, const RenderSettings& settings,
                      const PreparedScene& prepared, const CancelFlag* cancel) {
    g.setup_cancel = cancel;
    g.settings = settings;
    g.device = device;
    g.scene = prepared;  // what the pipeline keeps of it (PipelineScene)
    throw_if_cancelled(cancel);
    g.thread = std::make_unique<gl::GlThread>(g.device);
    g.thread->call([&] {
        try {
            compile_programs(g.thread->context().programs(), g.scene.defines, settings.hash,
                             g.scene.light_tracing, cancel, g.programs);
            // The traversal's node count, in every program that traces rays.
            const std::uint32_t node_count =
                g.two_level ? g.two_level->top_node_count : g.bvh->node_count;
            for (const gl::ComputeProgram* p : {g.programs.eye, g.programs.photon}) {
                p->use();
                glUniform1ui(p->uniform("bvh_node_count"), node_count);
            }
            throw_if_cancelled(cancel);
            if (settings.profile) {
                glGenQueries(5, g.timer.queries);
                gl::count_gl_objects(gl::GlObject::Query, 5);
            }
            glGenBuffers(1, &g.buffers.frame);
            gl::count_gl_objects(gl::GlObject::Buffer, 1);
            glBindBuffer(GL_UNIFORM_BUFFER, g.buffers.frame);
            glBufferData(GL_UNIFORM_BUFFER, sizeof(FrameBlock), &g.scene.frame, GL_DYNAMIC_DRAW);
            glBindBufferBase(GL_UNIFORM_BUFFER, BINDING_FRAME, g.buffers.frame);
            upload_scene(g, scene, prepared);
            allocate_pass_state(g, prepared);
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
