#include "render/renderer.h"

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
#include "render/texture_atlas.h"
#include "scene/scene_validation.h"
#include "render/rng_seed.h"

namespace glslppm {
namespace {

constexpr GLuint kLocalSize = 64;
constexpr float kPi = 3.14159265358979f;

std::uint32_t next_power_of_two(std::uint64_t v) {
    std::uint64_t p = 1;
    while (p < v) p <<= 1;
    return static_cast<std::uint32_t>(p);
}

// One 32-bit hash of the seed, pass and stage for the PCG generator's per-dispatch seed.
std::uint32_t mix_seed(std::uint64_t seed, std::uint64_t pass, std::uint32_t stage) {
    std::uint64_t z = seed * 0x9E3779B97F4A7C15ull + pass * 0xBF58476D1CE4E5B9ull + stage;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return static_cast<std::uint32_t>(z ^ (z >> 31));
}

// Which images the render needs: base-colour textures of materials on triangles that have
// uvs, and the environment map. Bad indices are errors; a texture without uvs is a warning.
struct TextureUse {
    bool materials = false, environment = false;
    std::vector<bool> used;  // per scene texture
};

TextureUse texture_use(const Scene& scene, const SceneGeometry& geometry,
                       std::vector<std::string>& warnings) {
    TextureUse use;
    use.used.assign(scene.textures.size(), false);
    for (std::size_t k = 0; k < scene.materials.size(); ++k) {
        const int t = scene.materials[k].color_texture;
        if (t < 0) continue;  // indices were checked by validate_scene
        if (geometry.mesh.uvs.empty()) {
            warnings.push_back("materials[" + std::to_string(k) + "] has a texture but the mesh "
                               "has no uvs: its colour is used instead");
            continue;
        }
        use.used[static_cast<std::size_t>(t)] = true;
        use.materials = true;
    }
    if (scene.environment_texture >= 0) {
        use.used[static_cast<std::size_t>(scene.environment_texture)] = true;
        use.environment = true;
    }
    return use;
}

}  // namespace

struct Renderer::Gpu {
    std::unique_ptr<gl::GlThread> thread;
    RenderSettings settings;
    PackedBvh bvh;
    EmitterTable emitters;
    SceneBounds bounds;
    FrameBlock frame{};
    gl::Defines defines;
    std::string variant;
    std::uint32_t pixels = 0, photon_threads = 0, hash_cells = 0;
    std::uint64_t passes = 0;
    double seconds = 0.0;
    std::atomic<bool> cancel{false};
    const CancelFlag* setup_cancel = nullptr;  // the constructor's, polled per buffer
    float initial_radius = 0.0f;
    std::size_t gpu_bytes = 0;

    GLuint ubo = 0;
    GLuint queries[5] = {0, 0, 0, 0, 0};  // stage boundaries when profiling
    double stage_seconds[4] = {0, 0, 0, 0};
    std::vector<GLuint> buffers;  // every SSBO, deleted together
    GLuint atlases[2] = {0, 0};   // sRGB8 and float array textures
    std::vector<std::string> warnings;
    int programs_compiled = 0, programs_reused = 0;
    double compile_seconds = 0.0;
    GLuint film = 0, counters = 0, pixel_stats = 0, photons = 0, hash = 0, radius_stats = 0;

    const gl::ComputeProgram* eye = nullptr;
    const gl::ComputeProgram* photon = nullptr;
    const gl::ComputeProgram* hash_a = nullptr;   // insert / count
    const gl::ComputeProgram* hash_b = nullptr;   // winner / scatter
    const gl::ComputeProgram* scan[3] = {nullptr, nullptr, nullptr};
    const gl::ComputeProgram* gather = nullptr;
    const gl::ComputeProgram* end_pass = nullptr;
    const gl::ComputeProgram* resolve = nullptr;
    const gl::ComputeProgram* radius_reduce = nullptr;

    // Before anything is allocated for it: a buffer larger than the driver allows is an
    // error that says what to lower (llvmpipe allows 128 MiB).
    static void require_fits(std::size_t bytes, const char* what) {
        GLint64 largest = 0;
        glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &largest);
        if (largest > 0 && bytes > static_cast<std::size_t>(largest))
            throw gl::GlError(std::string(what) + " needs " + std::to_string(bytes >> 20) +
                              " MiB, more than this GPU's largest storage buffer (" +
                              std::to_string(largest >> 20) +
                              " MiB): lower the resolution or the photons per pass");
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

    void set_rng_seed(const gl::ComputeProgram& program, std::uint32_t stage) {
        const GLint location = program.uniform("u_rng_seed");
        if (location >= 0) {
            program.use();
            glUniform1ui(location, mix_seed(settings.seed, passes, stage));
        }
    }

    void upload_frame() {
        glBindBuffer(GL_UNIFORM_BUFFER, ubo);
        glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof(FrameBlock), &frame);
    }

    void mark(int stage) {
        if (settings.profile) glQueryCounter(queries[stage], GL_TIMESTAMP);
    }

    void run_pass() {
        const GLbitfield ssbo = GL_SHADER_STORAGE_BARRIER_BIT;
        frame.pass_index = static_cast<std::uint32_t>(passes);
        upload_frame();

        mark(0);
        set_rng_seed(*eye, 0);
        dispatch(*eye, pixels);
        if (settings.profile) glMemoryBarrier(ssbo);
        mark(1);
        set_rng_seed(*photon, 1);
        dispatch(*photon, photon_threads);
        glMemoryBarrier(ssbo | GL_BUFFER_UPDATE_BARRIER_BIT);
        mark(2);

        // Empty cells: key "infinite", no photons.
        const GLuint empty_stochastic[4] = {0xFFFFFFFFu, 0u, 0u, 0u};
        const GLuint empty_exact[4] = {0u, 0u, 0u, 0u};
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, hash);
        glClearBufferData(GL_SHADER_STORAGE_BUFFER, GL_RGBA32UI, GL_RGBA_INTEGER, GL_UNSIGNED_INT,
                          settings.hash == HashMode::Exact ? empty_exact : empty_stochastic);
        glMemoryBarrier(ssbo);
        dispatch(*hash_a, photon_threads);
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
        dispatch(*hash_b, photon_threads);
        glMemoryBarrier(ssbo);
        mark(3);
        dispatch(*gather, pixels);
        glMemoryBarrier(ssbo);
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

Renderer::Renderer(const Scene& scene, const RenderSettings& settings, const CancelFlag* cancel)
    : settings_(settings), gpu_(std::make_unique<Gpu>()) {
    validate(settings);
    validate_scene(scene);
    Gpu& g = *gpu_;
    g.settings = settings;
    g.setup_cancel = cancel;

    // Area lights join the geometry; textures count only where the mesh has uvs for them.
    SceneGeometry geometry = with_area_lights(scene);
    const TextureUse use = texture_use(scene, geometry, g.warnings);
    if (!use.materials) geometry.mesh.uvs = {};  // no texture lookups: no uvs uploaded
    const ValidMesh mesh =
        validate_mesh(geometry.mesh, static_cast<std::uint32_t>(geometry.materials.size()));
    if (mesh.kept.empty())
        throw SceneError("the scene has no geometry: nothing to render (" +
                         std::to_string(mesh.stats.degenerate_dropped) +
                         " degenerate triangles dropped)");
    BvhBuildOptions options;
    options.leaf_size = settings.leaf_size;
    options.cancel = cancel;
    g.bvh = build_packed_bvh(mesh, options, 6);
    g.bounds = scene_bounds(g.bvh);
    // float32 positions, radii and ray offsets hold from about 1e-14 to 1e11 units across
    // (tests/python/test_geometry_extremes.py): outside that, say so rather than render black.
    const double extent = glm::length(glm::dvec3(g.bounds.hi) - glm::dvec3(g.bounds.lo));
    if (!(extent >= 1e-14 && extent <= 1e11)) {
        char size[32];
        std::snprintf(size, sizeof size, "%.3g", extent);
        throw SceneError(std::string("the scene is ") + size +
                         " units across, outside the 1e-14 to 1e11 that 32-bit floats "
                         "render: scale it (Blender: the objects or the unit scale)");
    }
    std::unique_ptr<EnvironmentMap> environment;
    if (use.environment) {
        environment = std::make_unique<EnvironmentMap>(build_environment_map(
            scene.textures[static_cast<std::size_t>(scene.environment_texture)],
            scene.environment));
    }
    throw_if_cancelled(cancel);
    g.emitters = build_emitters(scene, geometry.materials, g.bvh, g.bounds, environment.get());
    throw_if_cancelled(cancel);

    // The variant: only what this scene uses is compiled (DESIGN.md, "model only what a
    // scene requires").
    bool conductor = false, dielectric = false;
    for (std::uint32_t t = 0; t < g.bvh.triangle_count; ++t) {
        const auto kind = geometry.materials[static_cast<std::size_t>(
                                              std::bit_cast<int>(g.bvh.triangles[3 * t].w))]
                              .kind;
        conductor |= kind == MaterialKind::Conductor;
        dielectric |= kind == MaterialKind::Dielectric;
    }
    std::vector<std::string> features;
    auto feature = [&](bool on, const char* define, const char* name) {
        if (!on && !settings.full_variant) return;
        g.defines.push_back({define, "1"});
        features.push_back(name);
    };
    feature(!g.bvh.normals.empty(), "HAS_NORMALS", "normals");
    feature(scene.camera.projection == Projection::Perspective && scene.camera.aperture_radius > 0.0f,
            "HAS_DEPTH_OF_FIELD", "depth-of-field");
    feature(scene.camera.projection == Projection::Orthographic, "HAS_ORTHOGRAPHIC", "orthographic");
    feature(conductor, "HAS_CONDUCTOR", "conductor");
    feature(dielectric, "HAS_DIELECTRIC", "dielectric");
    feature(g.emitters.has[0], "HAS_TRIANGLE_EMITTERS", "area-lights");
    feature(g.emitters.has[1], "HAS_POINT_LIGHTS", "point-lights");
    feature(g.emitters.has[2], "HAS_SPOT_LIGHTS", "spot-lights");
    feature(g.emitters.has[3], "HAS_SUN_LIGHTS", "sun-lights");
    feature(g.emitters.has[4] || glm::length(scene.environment) > 0.0f, "HAS_ENVIRONMENT",
            "environment");
    feature(use.materials, "HAS_TEXTURES", "textures");
    feature(use.environment, "HAS_ENVIRONMENT_MAP", "environment-map");
    // Not features but outputs: the full variant leaves them as the settings say.
    if (settings.transparent) {
        g.defines.push_back({"FILM_TRANSPARENT", "1"});
        features.push_back("transparent");
        if (settings.transparent_glass) {
            g.defines.push_back({"FILM_TRANSPARENT_GLASS", "1"});
            features.push_back("transparent-glass");
        }
    }
    // Light sampling at the visible points (shaders/common/light_sampling.glsl) is compiled
    // only when asked for; its shadow rays skip the surfaces that cast no shadow (area lights,
    // objects with shadow visibility off) where the scene has them.
    if (settings.direct_light == DirectLight::Sampled) {
        g.defines.push_back({"DIRECT_LIGHT_SAMPLED", "1"});
        bool shadowless = settings.full_variant;
        for (std::uint32_t flags : geometry.flags)
            shadowless |= (flags & (kMaterialLightSurface | kMaterialCastsNoShadow)) != 0;
        if (shadowless) g.defines.push_back({"HAS_SHADOWLESS_SURFACES", "1"});
    }
    g.defines.push_back({settings.rng == RngKind::Pcg ? "RNG_PCG" : "RNG_PAPER", "1"});
    g.defines.push_back({settings.hash == HashMode::Exact ? "HASH_EXACT" : "HASH_STOCHASTIC", "1"});
    g.defines.push_back({"LOCAL_SIZE", std::to_string(kLocalSize) + "u"});
    g.defines.push_back({"RADIUS_STATS_THREADS", std::to_string(kRadiusStatsThreads) + "u"});
    features.push_back("rng=" + to_string(settings.rng));
    features.push_back("hash=" + to_string(settings.hash));
    features.push_back("direct=" + to_string(settings.direct_light));
    for (const std::string& f : features) g.variant += (g.variant.empty() ? "" : ",") + f;

    // Sizes and the frame constants.
    g.pixels = static_cast<std::uint32_t>(settings.width) * static_cast<std::uint32_t>(settings.height);
    g.photon_threads = settings.photons_per_pass;
    g.hash_cells = next_power_of_two(std::max<std::uint64_t>(2ull * g.photon_threads, 1024));
    const float diagonal = glm::length(g.bounds.hi - g.bounds.lo);
    const Camera& cam = scene.camera;
    // The whole frame (larger than the image when the image is a render region).
    const bool region = cam.full_width > 0;
    if (region && (cam.region_x + settings.width > cam.full_width ||
                   cam.region_y + settings.height > cam.full_height))
        throw std::invalid_argument("camera region: the image (" +
                                    std::to_string(settings.width) + "x" +
                                    std::to_string(settings.height) + " at " +
                                    std::to_string(cam.region_x) + ", " +
                                    std::to_string(cam.region_y) + ") does not fit in the " +
                                    std::to_string(cam.full_width) + "x" +
                                    std::to_string(cam.full_height) + " frame");
    const int frame_width = region ? cam.full_width : settings.width;
    const int frame_height = region ? cam.full_height : settings.height;
    // The film's height over its width; pixels may be non-square.
    const float aspect = static_cast<float>(frame_height) * cam.pixel_aspect /
                         static_cast<float>(frame_width);
    const bool wide = static_cast<float>(frame_width) >=
                      static_cast<float>(frame_height) * cam.pixel_aspect;
    const float tan_x = std::tan(0.5f * cam.fov_x);
    const float tan_larger = wide ? tan_x : tan_x * aspect;
    FrameBlock& f = g.frame;
    f.camera_to_world = cam.to_world;
    glm::vec2 half_extent, shift;
    if (cam.projection == Projection::Orthographic) {
        // Blender's ortho_scale spans the larger image side.
        const float half_larger = 0.5f * cam.ortho_scale;
        const float half_x = wide ? half_larger : half_larger / aspect;
        half_extent = glm::vec2(half_x, half_x * aspect);
        shift = glm::vec2(2.0f * cam.shift_x * half_larger, 2.0f * cam.shift_y * half_larger);
    } else {
        half_extent = glm::vec2(tan_x, tan_x * aspect);
        shift = glm::vec2(2.0f * cam.shift_x * tan_larger, 2.0f * cam.shift_y * tan_larger);
    }
    if (region) {
        // The window's half extent and centre in the frame's film coordinates ([-1, 1],
        // y up, row 0 at the top).
        const glm::vec2 frame(frame_width, frame_height);
        const glm::vec2 size(settings.width, settings.height);
        const glm::vec2 corner(cam.region_x, cam.region_y);
        const glm::vec2 centre((2.0f * corner.x + size.x) / frame.x - 1.0f,
                               1.0f - (2.0f * corner.y + size.y) / frame.y);
        shift = shift + half_extent * centre;
        half_extent = half_extent * size / frame;
    }
    f.film_half_extent = half_extent;
    f.film_shift = shift;
    f.orthographic = cam.projection == Projection::Orthographic ? 1u : 0u;
    f.aperture_radius = cam.aperture_radius;
    f.focus_distance = cam.focus_distance;
    f.scene_lo = g.bounds.lo;
    f.ray_offset_floor = 1e-3f * diagonal;
    f.scene_center = g.bounds.center();
    f.scene_radius = g.bounds.radius();
    f.world_radiance = scene.environment;
    f.environment_from_world = glm::mat4(glm::transpose(scene.environment_to_world));
    if (environment) {
        f.environment_texture = scene.environment_texture;
        f.environment_cdf_width = environment->width;
        f.environment_cdf_height = environment->height;
    }
    f.image_width = static_cast<std::uint32_t>(settings.width);
    f.image_height = static_cast<std::uint32_t>(settings.height);
    f.photon_threads = g.photon_threads;
    f.hash_cell_count = g.hash_cells;
    f.max_depth = static_cast<std::uint32_t>(settings.max_depth);
    f.emitter_count = static_cast<std::uint32_t>(g.emitters.count);
    // Automatic radius: two pixel footprints at the distance of what the camera sees (the
    // median hit distance of a 5x5 grid of rays through the film), at most 5% of the
    // scene's diagonal.
    float radius = settings.initial_radius;
    if (radius <= 0.0f) {
        const glm::vec3 eye(cam.to_world[3]);
        std::vector<float> distances;
        for (int j = 0; j < 5; ++j) {
            for (int i = 0; i < 5; ++i) {
                const glm::vec2 ndc((i + 0.5f) / 2.5f - 1.0f, 1.0f - (j + 0.5f) / 2.5f);
                const glm::vec2 film = ndc * f.film_half_extent + f.film_shift;
                const bool ortho = cam.projection == Projection::Orthographic;
                const glm::vec3 o = ortho ? glm::vec3(film, 0.0f) : glm::vec3(0.0f);
                const glm::vec3 d = ortho ? glm::vec3(0, 0, -1) : glm::vec3(film, -1.0f);
                Ray ray{glm::vec3(cam.to_world * glm::vec4(o, 1.0f)),
                        glm::normalize(glm::vec3(cam.to_world * glm::vec4(d, 0.0f)))};
                const Hit hit = closest_hit(g.bvh, ray);
                if (hit.triangle >= 0) distances.push_back(hit.t);
            }
        }
        float distance = glm::length(g.bounds.center() - eye);
        if (!distances.empty()) {
            std::nth_element(distances.begin(), distances.begin() + distances.size() / 2,
                             distances.end());
            distance = distances[distances.size() / 2];
        }
        const float footprint =
            cam.projection == Projection::Orthographic
                ? cam.ortho_scale / static_cast<float>(std::max(frame_width, frame_height))
                : 2.0f * distance * tan_x / static_cast<float>(frame_width);
        radius = std::min(2.0f * footprint, 0.05f * diagonal);
        if (!(radius > 0.0f)) radius = 0.01f * diagonal;
        radius *= settings.radius_scale;
    }
    g.initial_radius = radius;
    f.sppm_alpha = settings.alpha;
    f.radius_floor = 1e-5f * diagonal;

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
            g.make_buffer(BINDING_EMITTERS, bytes(g.emitters.records), g.emitters.records.data(),
                          "lights");
            std::vector<GpuMaterial> materials;
            for (std::size_t k = 0; k < geometry.materials.size(); ++k) {
                const Material& m = geometry.materials[k];
                materials.push_back({m.color, static_cast<float>(m.kind), m.emission, m.ior,
                                     use.materials ? m.color_texture : -1,
                                     static_cast<std::uint32_t>(geometry.flags[k]), {0, 0}});
            }
            g.make_buffer(BINDING_MATERIALS, bytes(materials), materials.data(), "materials");
            Counters counters{std::bit_cast<std::uint32_t>(radius), 0, 0, 0, 0, 0, 0, 0};
            g.counters = g.make_buffer(BINDING_COUNTERS, sizeof(counters), &counters, "counters");

            const std::size_t px = g.pixels, ph = g.photon_threads;
            Gpu::require_fits(px * 3 * 16, "visible points");
            Gpu::require_fits(ph * 3 * 16, "photons");
            Gpu::require_fits(std::size_t(g.hash_cells) * 16, "hash cells");
            g.make_buffer(BINDING_VISIBLE_POINTS, px * 3 * 16, nullptr, "visible points");
            std::vector<glm::vec4> stats(px * 2, glm::vec4(0.0f));
            for (std::size_t i = 0; i < px; ++i) stats[2 * i + 1].x = radius;
            g.pixel_stats = g.make_buffer(BINDING_PIXEL_STATS, bytes(stats), stats.data(), "pixel statistics");
            stats.assign(px * 2, glm::vec4(0.0f));
            g.make_buffer(BINDING_DIRECT_LIGHT, bytes(stats), stats.data(), "direct light");
            std::vector<glm::vec4> paths(ph * 3, glm::vec4(0.0f));
            for (std::size_t i = 0; i < ph; ++i) paths[3 * i].w = -1.0f;
            g.make_buffer(BINDING_PHOTON_PATHS, bytes(paths), paths.data(), "photon paths");
            paths.assign(ph * 3, glm::vec4(0.0f));
            g.photons = g.make_buffer(BINDING_PHOTONS, bytes(paths), paths.data(), "photons");
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
    s.emitters = g.emitters.count;
    s.bvh_seconds = g.bvh.stats.total_seconds();
    s.bvh_bytes_per_triangle = g.bvh.stats.bytes_per_triangle;
    s.gpu_bytes = g.gpu_bytes;
    s.eye_seconds = g.stage_seconds[0];
    s.photon_seconds = g.stage_seconds[1];
    s.hash_seconds = g.stage_seconds[2];
    s.gather_seconds = g.stage_seconds[3];
    s.warnings = g.warnings;
    s.programs_compiled = g.programs_compiled;
    s.programs_reused = g.programs_reused;
    s.compile_seconds = g.compile_seconds;
    return s;
}

}  // namespace glslppm
