// Renderer::set_up: one worker's GL thread and context, its programs and its buffers
// (the rest of the Renderer is in renderer.cpp; results read back in renderer_readback.cpp).
#include <epoxy/gl.h>

#include <algorithm>
#include <chrono>

#include "gl/object_counts.h"
#include "render/memory_estimate.h"
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
                      bool light_tracing, bool deforms, const CancelFlag* cancel,
                      StagePrograms& s) {
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
    if (deforms) {
        s.deform_vertices = program("deform_mesh.comp", "PHASE_VERTICES");
        s.deform_refit = program("deform_mesh.comp", "PHASE_REFIT");
    }
    for (const gl::ComputeProgram* p :
         {s.eye, s.photon, s.hash_clear, s.hash_a, s.hash_b, s.scan[0], s.scan[1], s.scan[2],
          s.gather, s.end_pass, s.restart, s.resolve, s.light_splats, s.deform_vertices,
          s.deform_refit}) {
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
    g.buffers.bvh_nodes =
        g.make_buffer(BINDING_BVH_NODES, bytes(bvh.nodes), bvh.nodes.data(), "BVH nodes");
    g.make_buffer(BINDING_BVH_LINKS, bytes(bvh.links), bvh.links.data(), "BVH links");
    g.buffers.triangles =
        g.make_buffer(BINDING_TRIANGLES, bytes(bvh.triangles), bvh.triangles.data(), "triangles");
    if (instances && !instances->empty())
        g.buffers.instances =
            g.make_buffer(BINDING_INSTANCES, bytes(*instances), instances->data(), "instances");
    if (!bvh.normals.empty())
        g.buffers.normals =
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
        g.make_buffer(BINDING_EMITTERS, bytes(emitters.records), emitters.records.data(),
                      "emitters");
    g.buffers.materials = g.make_buffer(BINDING_MATERIALS, bytes(prepared.material_records),
                                        prepared.material_records.data(), "materials");
    g.buffers.counters = g.make_buffer(BINDING_COUNTERS, sizeof(Counters), nullptr, "counters");
}

// The photon steps of a pass stored side by side, and each step's slot, are the estimator's
// (DensityEstimator::photon_steps_per_gather, photon_slot). The sizes are
// render/memory_estimate.h's, which the memory estimate gives too.
PassStateShape worker_pass_state_shape(const Renderer::Gpu& g) {
    const RenderSettings& settings = g.settings;
    PassStateShape shape;
    shape.pixels = g.scene.pixels;
    shape.photon_threads = g.scene.photon_threads;
    shape.hash_cells = g.scene.hash_cells;
    shape.pass_stride = static_cast<std::size_t>(g.scene.pass_layout.stride);
    shape.light_tracing = g.scene.light_tracing;
    if (shape.light_tracing)
        shape.light_splat_groups = static_cast<std::size_t>(g.scene.pass_layout.light_groups);
    shape.exact_hash = settings.hash == HashMode::Exact;
    shape.paper_rng = settings.rng == RngKind::Paper;
    const DensityEstimator& estimator = density_estimator(settings.estimator);
    shape.photon_slot = estimator.photon_slot(g.scene.photon_threads);
    GLint64 largest = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &largest);
    shape.steps_per_gather = estimator.photon_steps_per_gather(
        static_cast<std::uint32_t>(shape.photon_slot), largest, settings.max_bounces);
    if (const std::uint32_t slots = vcm_merge_slots(settings, largest)) {
        shape.photon_slot = g.scene.photon_threads;
        shape.steps_per_gather = slots;  // VCM's merging: its light vertices' slots
    }
    return shape;
}

// The passes' state: per pixel (visible points, statistics, direct light, film, render
// passes) and per photon (paths, stored photons, hash cells, generator states).
void allocate_pass_state(Renderer::Gpu& g) {
    const RenderSettings& settings = g.settings;
    PipelineBuffers& b = g.buffers;
    const PassStateShape shape = worker_pass_state_shape(g);
    const PassStateBytes sizes = pass_state_bytes(shape);
    g.photon_slot = static_cast<std::uint32_t>(shape.photon_slot);
    g.steps_per_gather = static_cast<std::uint32_t>(shape.steps_per_gather);
    const std::size_t allocated_before = b.bytes;
    g.require_fits(sizes.visible_points, "visible points", true);
    g.require_fits(sizes.photon_paths, "photons");
    g.require_fits(sizes.hash_cells, "hash cells");
    b.bytes_per_pixel = sizes.bytes_per_pixel;
    b.bytes_per_photon = sizes.bytes_per_photon;
    g.make_buffer(BINDING_VISIBLE_POINTS, sizes.visible_points, nullptr, "visible points");
    // Their first contents: restart_film(), as at every restart.
    b.pixel_stats =
        g.make_buffer(BINDING_PIXEL_STATS, sizes.pixel_stats, nullptr, "pixel statistics");
    b.direct_light =
        g.make_buffer(BINDING_DIRECT_LIGHT, sizes.direct_light, nullptr, "direct light");
    b.photon_paths =
        g.make_buffer(BINDING_PHOTON_PATHS, sizes.photon_paths, nullptr, "photon paths");
    g.require_fits(sizes.photons, "photons");
    b.photons = g.make_buffer(BINDING_PHOTONS, sizes.photons, nullptr, "photons");
    const GLuint zero[4] = {0, 0, 0, 0};
    glClearBufferData(GL_SHADER_STORAGE_BUFFER, GL_RGBA32UI, GL_RGBA_INTEGER, GL_UNSIGNED_INT,
                      zero);
    if (shape.paper_rng) {
        const std::vector<glm::vec4> seeds =
            paper_rng_seeds(shape.pixels + shape.photon_threads, settings.seed);
        g.make_buffer(BINDING_RNG_STATES, bytes(seeds), seeds.data(), "generator states");
    }
    b.hash = g.make_buffer(BINDING_HASH_CELLS, sizes.hash_cells, nullptr, "hash cells");
    g.make_buffer(BINDING_HASH_SORTED, sizes.sorted_photons, nullptr, "sorted photons");
    b.film = g.make_buffer(BINDING_FILM, sizes.film, nullptr, "film");
    if (sizes.pass_films > 0) {
        g.require_fits(sizes.pass_films, "render passes", true);
        b.pass_films =
            g.make_buffer(BINDING_PASS_FILMS, sizes.pass_films, nullptr, "render passes");
    }
    b.radius_stats =
        g.make_buffer(BINDING_RADIUS_STATS, sizes.radius_stats, nullptr, "radius statistics");
    if (sizes.light_splats > 0) {
        // kLightSplatBytes a pixel, and as much per light group (common/light_splats.glsl);
        // zeroed by restart_film().
        g.require_fits(sizes.light_splats, "light tracing's splats", true);
        b.light_splats =
            g.make_buffer(BINDING_LIGHT_SPLATS, sizes.light_splats, nullptr, "light splats");
    }
    // What was allocated, beside what was planned: stats()["pass_state_bytes"], which the
    // tests compare with memory_estimate.
    b.pass_state_bytes = b.bytes - allocated_before;
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
            const bool deforms = g.scene.motion && !g.scene.motion->meshes.empty();
            compile_programs(g.thread->context().programs(), g.scene.defines, settings.hash,
                             g.scene.light_tracing, deforms, cancel, g.programs);
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
            allocate_pass_state(g);
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
