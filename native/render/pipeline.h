// The GPU pipeline of one Renderer (native/render/renderer.h keeps it behind a pointer): the
// GL thread, the prepared scene it was built from, its stage programs and its buffers in
// named groups, and a pass as its stages (pbrt-v4's wavefront loop): trace_eye,
// trace_photons, hash_photons, gather, end_pass. Only the Renderer's own sources include
// this file: renderer.cpp (the passes' scheduling, restarts), renderer_setup.cpp (programs
// and buffers made), pipeline_buffers.cpp (buffers), pass_stages.cpp (the stages),
// renderer_readback.cpp (film, passes, stats).
#pragma once

#include <epoxy/gl.h>

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "bvh/packed_bvh.h"
#include "bvh/two_level_bvh.h"
#include "gl/buffer_reader.h"
#include "gl/gl_thread.h"
#include "gl/shader_program.h"
#include "render/density_estimator.h"
#include "render/gpu_layout.h"
#include "render/renderer.h"
#include "render/scene_preparation.h"
#include "render/texture_atlas.h"
#include "scene/cancel.h"

namespace glslppm {
namespace pipeline_detail {

constexpr GLuint kLocalSize = 64;

// One 32-bit hash of the seed, pass and stage for the PCG generator's per-dispatch seed.
inline std::uint32_t mix_seed(std::uint64_t seed, std::uint64_t pass, std::uint32_t stage) {
    std::uint64_t z = seed * 0x9E3779B97F4A7C15ull + pass * 0xBF58476D1CE4E5B9ull + stage;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return static_cast<std::uint32_t>(z ^ (z >> 31));
}

}  // namespace pipeline_detail

using pipeline_detail::kLocalSize;
using pipeline_detail::mix_seed;

// The compiled programs of the scene's variant, one per stage (and phase).
struct StagePrograms {
    const gl::ComputeProgram* eye = nullptr;
    const gl::ComputeProgram* photon = nullptr;
    const gl::ComputeProgram* hash_clear = nullptr;
    const gl::ComputeProgram* hash_a = nullptr;                       // insert / count
    const gl::ComputeProgram* hash_b = nullptr;                       // winner / scatter
    const gl::ComputeProgram* scan[3] = {nullptr, nullptr, nullptr};  // the exact hash's
    const gl::ComputeProgram* gather = nullptr;
    const gl::ComputeProgram* end_pass = nullptr;
    const gl::ComputeProgram* restart = nullptr;  // a film's first state
    const gl::ComputeProgram* resolve = nullptr;
    const gl::ComputeProgram* radius_reduce = nullptr;
    const gl::ComputeProgram* light_splats = nullptr;  // HAS_LIGHT_TRACING: a pass's splats folded in
    // Deforming meshes (deform_mesh.comp): their vertices, then their trees' boxes.
    const gl::ComputeProgram* deform_vertices = nullptr;
    const gl::ComputeProgram* deform_refit = nullptr;
    int compiled = 0, reused = 0;  // from source, from an earlier renderer's binaries
    double compile_seconds = 0.0;
};

// Every buffer and texture of the pipeline, named by what it holds; `ssbos` lists every
// storage buffer (deleted together). The scene's own (BVH, materials, ...) are bound once.
struct PipelineBuffers {
    GLuint frame = 0;                           // the FrameBlock's uniform buffer
    GLuint materials = 0, emitter_records = 0;  // replaced by update_tables
    GLuint film = 0, counters = 0, pixel_stats = 0, direct_light = 0, pass_films = 0;
    GLuint photon_paths = 0, photons = 0, hash = 0, radius_stats = 0;
    GLuint light_splats = 0;  // HAS_LIGHT_TRACING (common/light_splats.glsl)
    GLuint bvh_nodes = 0, instances = 0;  // rewritten per pass where instances move
    GLuint triangles = 0, normals = 0;    // rewritten per pass where meshes deform
    GLuint atlases[2] = {0, 0};  // sRGB8 and float array textures
    std::vector<GLuint> ssbos;
    gl::BufferReader reader;  // film, passes and photons read back
    std::size_t bytes = 0;
    std::size_t bytes_per_pixel = 0;  // the per-pixel buffers' bytes for one pixel
    double bytes_per_photon = 0.0;    // the per-photon buffers' bytes for one photon
    std::size_t pass_state_bytes = 0;  // allocate_pass_state's buffers (render/memory_estimate.h)
};

// A deforming mesh, deformed on the GPU each pass (deform_mesh.comp): its entries in the
// triangle table, its vertices' place in the steps' buffers (step s of vertex v at
// first_vertex + s vertex_count + v), and its bottom root's box over every step, padded,
// which the top level's leaves bound it by.
struct DeformScratch {
    bool traced = false;  // an instance traces it
    std::uint32_t first_entry = 0, entry_count = 0;
    std::uint32_t first_vertex = 0, vertex_count = 0;
    glm::vec3 root_lo{0.0f}, root_hi{0.0f};
};

// A moving area light's packed triangle: its MotionPlan::lights index, its index in the
// traced triangles (mesh 0's come first) and its place k in the light's fan (0, k+1, k+2).
struct AreaLightTriangle {
    std::size_t light = 0, packed = 0, local = 0;
};

// A moving emitting instance's packed triangle (MotionPlan::mesh_emitters[emitter], its
// triangle `local`), and its emitter record (-1: a triangle of a material that does not emit).
struct EmitterTriangle {
    std::size_t emitter = 0, packed = 0, local = 0;
    std::int32_t record = -1;
};

// Motion blur's per-pass copies (motion_pass.cpp): the two-level tree's top nodes and the
// instance records, rewritten at each pass's time and uploaded, the moving instances'
// record range and top leaves.
struct MotionScratch {
    std::vector<glm::vec4> top_nodes, records;
    std::vector<std::int32_t> leaf_of_instance;  // the top leaf of each record, -1 none
    std::size_t first_record = 0, end_record = 0;
    std::vector<DeformScratch> meshes;    // one per MotionPlan::meshes
    std::vector<std::size_t> refit_records;  // records whose top leaf moves: moving or deforming
    std::vector<std::int32_t> deformed_of_mesh;  // mesh index -> meshes' index, -1 none
    // The refit table's depths, deepest first: depth d's entries are [levels[d], levels[d+1]).
    std::vector<std::uint32_t> refit_levels;
    double refit_seconds = 0.0;  // host time moving instances and lights, refitting, all passes
    std::vector<glm::vec4> light_records;  // the moving lights' records, at the pass's time
    bool area_lights_traced = false;  // area_triangles found (render/area_light_motion.cpp)
    std::vector<AreaLightTriangle> area_triangles;
    bool mesh_emitters_traced = false;  // emitter_triangles found (render/emitter_motion.cpp)
    std::vector<EmitterTriangle> emitter_triangles;  // in packed order
};

// GPU time per stage when settings.profile: timestamps at the stages' boundaries.
struct StageTimer {
    GLuint queries[5] = {0, 0, 0, 0, 0};
    double seconds[4] = {0, 0, 0, 0};  // eye trace, photon trace, hashing, gather
};

struct Renderer::Gpu {
    std::unique_ptr<gl::GlThread> thread;
    int device = -1;
    RenderSettings settings;
    PipelineScene scene;  // as prepared; set_camera and update_tables change its frame
    // The MTBVH traced: one level, or two (shared by the workers; each uploads it). The
    // stats of what is traced (two levels: both).
    std::shared_ptr<const PackedBvh> bvh;
    std::shared_ptr<const TwoLevelBvh> two_level;
    BvhStats bvh_stats;
    StagePrograms programs;
    PipelineBuffers buffers;
    StageTimer timer;
    MotionScratch motion;

    // Photon steps stored side by side before one hash and gather, and each step's slot in
    // the photon buffer (DensityEstimator::photon_steps_per_gather, photon_slot).
    std::uint32_t steps_per_gather = 1, photon_slot = 0;
    std::uint64_t passes = 0;
    std::vector<std::uint64_t> pass_indices;  // independent passes: the indices this worker ran
    double seconds = 0.0;
    double submit_seconds = 0.0, wait_seconds = 0.0;  // host time within `seconds` (run_workers)
    std::atomic<bool> cancel{false};
    const CancelFlag* setup_cancel = nullptr;  // the constructor's, polled per buffer
    int camera_updates = 0, table_updates = 0, film_resets = 0;

    // Buffers (pipeline_buffers.cpp). The largest storage buffer a render may allocate: the
    // driver's (llvmpipe allows 128 MiB); for the per-pixel buffers, less where
    // settings.max_block_bytes caps it. 0: no limit known.
    std::size_t largest_block(bool per_pixel) const;
    // Before anything is allocated for it: a buffer larger than the driver allows is an
    // error that says what to lower.
    void require_fits(std::size_t bytes, const char* what, bool per_pixel = false) const;
    GLuint make_buffer(GLuint binding, std::size_t bytes, const void* data, const char* what);
    // Replaces a buffer's contents, its size too (a table that grew or shrank).
    void replace_buffer(GLuint id, std::size_t bytes, const void* data, const char* what);
    // The images as two array textures on units 0 (sRGB8) and 1 (float); 1x1 placeholders
    // when a kind is absent, so that every sampler is complete.
    void upload_atlas(const TextureAtlas& atlas);
    void upload_frame();
    Counters read_counters();
    void release();

    // A pass as its stages (pass_stages.cpp), with the estimator's differences asked of its
    // description (render/density_estimator.h). Passes that depend on each other (SPPM):
    // pass_index is the count of passes run before. Independent passes (PPPM): any index.
    // PhotonPaths::WithinPass traces the photon paths in photon_steps_per_pass steps, stored
    // side by side and hashed and gathered steps_per_gather at a time (gather_stored_steps).
    void run_pass(std::uint64_t pass_index);
    void begin_pass(std::uint64_t pass_index);
    // Motion blur (motion_pass.cpp): the camera into the frame and the moving instances into
    // the GPU's top level, at pass `pass_index`'s time; only where scene.motion. Deforming
    // meshes: their vertices, normals and bottom trees at time t.
    void move_to_shutter_time(std::uint64_t pass_index);
    void deform_meshes(double t);
    // Moving lamps: their emitter records at time t (render/light_motion.cpp).
    void move_lights(double t);
    void move_area_lights(double t);
    // Moving instances that emit light, placed once: their triangles, normals and emitter
    // records at time t (render/emitter_motion.cpp).
    void move_mesh_emitters(double t);
    void trace_eye(std::uint64_t pass_index);
    void trace_photons(std::uint64_t pass_index, std::uint32_t step);
    // PhotonPaths::AcrossPasses: before a film's first pass, photon steps that bring the
    // paths to their stationary state and count nothing.
    void warm_up_photon_paths();
    void hash_photons(std::uint32_t stored);
    void gather(bool mark_stage);
    void gather_stored_steps(std::uint32_t stored_steps, bool mark_stage);
    void end_pass();
    // The film's first state (a new renderer, a restart): no passes, every pixel's radius
    // the initial one, no direct light, every photon path to start from a light, counts
    // zero. Written by a dispatch (restart_film.comp): the host uploads nothing.
    void restart_film();
    void dispatch(const gl::ComputeProgram& program, std::uint32_t threads);
    void set_merge_slots(const gl::ComputeProgram& program);
    void set_rng_seed(const gl::ComputeProgram& program, std::uint64_t pass_index,
                      std::uint32_t stage);
    void mark(int stage);

    // Read back (renderer_readback.cpp). The film of this worker's passes (their mean);
    // into `out` (pixels x 4 floats; bottom_up: its bottom row first).
    std::vector<float> resolve_film();
    void resolve_film_into(float* out, bool bottom_up = false);
    // Render passes of this worker's passes (their mean), resolved on the CPU from the pass
    // films and the pixel statistics, as resolve_film() resolves Combined on the GPU: one
    // read back for all of them.
    // The passes asked, then with `groups` every light group's (render_passes.h).
    std::vector<std::vector<float>> resolve_passes(const std::vector<RenderPass>& wanted,
                                                   bool groups = false);

    static std::uint64_t total(std::uint32_t lo, std::uint32_t hi) {
        return (static_cast<std::uint64_t>(hi) << 32) | lo;
    }
};

}  // namespace glslppm
