// The SPPM renderer: owns a GL thread with its EGL context, the scene's MTBVH on the GPU and
// the per-pixel and per-photon state; runs passes (eye trace, photon trace, photon hashing,
// gather with the progressive update) and resolves the film on demand.
#pragma once

#include <cstdint>
#include <atomic>
#include <memory>
#include <string>
#include <utility>
#include <span>
#include <vector>

#include "render/settings.h"
#include "scene/cancel.h"
#include "scene/scene.h"

namespace glslppm {

struct PreparedScene;  // render/scene_preparation.h

// One worker's share of a render: the EGL device it ran on and its passes.
struct DeviceStats {
    int device = -1;                    // EGL device index (-1: surfaceless or the default)
    std::string renderer;               // GL_RENDERER
    std::uint64_t passes = 0;
    double seconds = 0.0;               // time this worker spent running passes
    // Of those seconds, the host's: issuing the passes' GL commands, and waiting for the GPU
    // to catch up (several workers: where time goes when the devices do not scale).
    double submit_seconds = 0.0;
    double wait_seconds = 0.0;
    double passes_per_second = 0.0;
};

struct RenderStats {
    std::uint64_t passes = 0;
    std::uint64_t photons_emitted = 0;  // photon paths started, 64-bit
    std::uint64_t rays = 0;
    double seconds = 0.0;               // time spent in run()
    double photons_per_second = 0.0;
    double rays_per_second = 0.0;
    double mean_radius = 0.0;
    double max_radius = 0.0;
    double initial_radius = 0.0;
    std::string renderer;               // GL_RENDERER
    std::string variant;                // the feature set the programs were compiled with
    std::string direct_light;           // "sampled", "sampled-no-mis" or "photons" (RenderSettings::direct_light)
    std::string estimator;              // "sppm" or "pppm"
    double radius_floor = 0.0;          // radii never shrink below it (scene-relative)
    // The pass indices run, as sorted half-open ranges [first, end) (pppm: any set).
    std::vector<std::pair<std::uint64_t, std::uint64_t>> pass_ranges;
    std::vector<DeviceStats> devices;   // one per worker
    std::string scene_hash;             // scene/scene_hash.h, 16 hex digits
    std::size_t triangles = 0;  // distinct: each instanced mesh counted once
    std::size_t degenerate_dropped = 0;
    // How instances were traced ("none", "two-level", "flattened"), why, how many, and the
    // triangles a flattened copy holds.
    std::string instancing;
    std::string instancing_reason;
    std::size_t instances = 0;
    std::size_t instanced_triangles = 0;
    // Motion blur (render/motion.h): "none", or what moves ("camera", "instances",
    // "deformation",
    // "camera,instances"), the moving instances, and the host's time moving them and
    // refitting the top level, all passes of all workers.
    std::string motion = "none";
    std::size_t moving_instances = 0;
    double motion_refit_seconds = 0.0;
    std::size_t emitters = 0;
    double bvh_seconds = 0.0;
    double bvh_bytes_per_triangle = 0.0;
    std::size_t gpu_bytes = 0;          // buffers this renderer allocated
    std::size_t gpu_bytes_per_pixel = 0;  // of the per-pixel buffers, for one pixel
    // Of the per-photon buffers (paths, stored photons, hash cells, generator states), for
    // one photon of a pass.
    double gpu_bytes_per_photon = 0.0;
    // One worker's pass-state buffers as allocated: memory_estimate's figure
    // (render/memory_estimate.h). A tiled render: the largest tile's.
    std::size_t pass_state_bytes = 0;
    // Image tiles rendered one after another (native/render/tiled_render.h); 1 untiled.
    int tiles = 1;
    // GPU time per stage (settings.profile): eye trace, photon trace, hashing, gather.
    double eye_seconds = 0.0, photon_seconds = 0.0, hash_seconds = 0.0, gather_seconds = 0.0;
    std::vector<std::string> warnings;  // what was approximated (downscaled images, ...)
    // Programs of this renderer's variant compiled from source, and loaded from binaries an
    // earlier renderer of the same variant left (gl/program_binaries.h); the time both took.
    int programs_compiled = 0;
    int programs_reused = 0;
    double compile_seconds = 0.0;
    // Restarts without a new MTBVH or programs: set_camera, update_tables and reset_film
    // calls that changed something (the viewport's cheap restarts).
    int camera_updates = 0;
    int table_updates = 0;
    int film_resets = 0;
};

class Renderer {
public:
    // Validates the scene and settings (std::invalid_argument / SceneError), builds the
    // MTBVH, creates the GL context (gl::GlError) and compiles the programs
    // (gl::ShaderError). The scene's arrays may be freed afterwards. Setting `cancel` (from
    // another thread) meanwhile stops the set-up within milliseconds: Cancelled.
    Renderer(const Scene& scene, const RenderSettings& settings,
             const CancelFlag* cancel = nullptr);
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    // Runs `passes` passes and waits for the GPU to finish them; returns how many ran
    // (fewer when cancel() was called meanwhile). An estimator of independent passes (PPPM,
    // render/density_estimator.h): the next pass indices from settings.first_pass on
    // (skipping any run_passes() ran), dealt to the workers as they become free.
    int run(int passes);
    // Independent passes only (PPPM): runs exactly these pass indices (none run before by
    // this renderer: std::invalid_argument), dealt to the workers as they become free.
    int run_passes(const std::vector<std::uint64_t>& indices);
    // Stops a run in progress after its current pass; safe from any thread.
    void cancel();
    // Stops every run for good, in progress or yet to start: a renderer being closed (a
    // cancel() that comes before a run begins is otherwise forgotten, since a run clears it).
    void stop();
    // Tests only: sets the 64-bit count of photon paths started, so that a short test can
    // carry it past 2^32.
    void debug_set_photons_emitted(std::uint64_t count);
    // Starts the image again: no passes, every pixel's radius back to the initial one, the
    // photon paths and 64-bit counts restarted, on every worker; independent passes: run()
    // starts again from settings.first_pass. Scene, MTBVH and programs stay.
    void reset_film();
    // Looks through another camera at the same image size, then reset_film(); no MTBVH
    // build, no upload but the frame constants. Returns false and changes nothing when the
    // camera needs other programs (perspective <-> orthographic, depth of field on <-> off):
    // build a new Renderer then. Throws SceneError for a camera that fails validation.
    bool set_camera(const Camera& camera);
    // The materials, lights and world of `scene`, which must have this renderer's geometry
    // (the same triangles; area lights are geometry), then reset_film(); the MTBVH stays.
    // Returns false and changes nothing when the change needs other programs or images
    // (a new kind of material or light, another texture, an environment map) or the
    // geometry's size differs: build a new Renderer then.
    bool update_tables(const Scene& scene);
    // Linear RGBA, height x width x 4 floats, row 0 at the top. With several workers, their
    // films merged (render/film_merge.h).
    std::vector<float> film();
    // The same into the caller's memory (height x width x 4 floats, else invalid_argument):
    // a viewport or progressive update that reuses one buffer writes no new pages.
    // bottom_up: the bottom row first, as Blender's images and GPU textures store them.
    void film_into(std::span<float> out, bool bottom_up = false);
    // One of settings.passes (render/render_passes.h), as film() gives Combined: height x
    // width x 4 floats (Depth in the first channel), the mean over the passes run.
    // std::invalid_argument for a pass the settings did not enable.
    std::vector<float> render_pass(RenderPass pass);
    // Several at once, in the order asked, with one read back of the pass films per worker
    // (what the add-on streams into Blender's result).
    std::vector<std::vector<float>> render_passes(const std::vector<RenderPass>& wanted);
    // Every light group's pass (Scene::light_groups, docs/light_groups.md), in the scene's
    // order, as render_pass gives a pass: height x width x 4 floats; none without groups.
    std::vector<std::vector<float>> light_group_passes();
    const std::vector<std::string>& light_groups() const { return light_groups_; }
    RenderStats stats();
    // The photons stored by the last pass, 12 floats each: position, key bits, direction
    // towards where it came from, the record word (shaders/common/sppm_buffers.glsl: its
    // path's class with the light split's passes, shaders/common/pass_films.glsl: 0 direct,
    // 1 indirect, 2 caustic, else 0; plus 4 times the path's bounce word,
    // shaders/common/bounces.glsl), flux, and
    // the side word (shaders/common/sppm_buffers.glsl: a positive integer) if stored else 0
    // (tests and debugging).
    std::vector<float> photons();
    const RenderSettings& settings() const { return settings_; }

    // One worker's GPU pipeline (render/pipeline.h), complete only in the Renderer's sources.
    struct Gpu;

private:
    static void set_up(Gpu& g, int device, const Scene& scene, const RenderSettings& settings,
                       const PreparedScene& prepared, const CancelFlag* cancel);
    int run_independent(int passes);  // run()'s next pass indices, dealt to the workers
    int run_in_order(int passes);     // run()'s passes that depend on each other: one worker
    int run_workers(const std::vector<std::uint64_t>& indices);
    void restart_passes();  // after a restart of every worker's film
    std::vector<float> merged_film();  // several workers' films, merged by their passes
    // Passes and then, with `groups`, every light group's, merged over the workers.
    std::vector<std::vector<float>> merged_passes(const std::vector<RenderPass>& wanted,
                                                  bool groups);

    RenderSettings settings_;
    std::vector<std::string> light_groups_;   // the scene's light groups' names
    std::vector<std::unique_ptr<Gpu>> gpus_;  // one worker per device
    std::uint64_t next_pass_ = 0;             // independent passes: run()'s next pass index
    std::atomic<bool> stopped_{false};        // stop(): no pass runs any more
    std::size_t flatten_max_triangles_ = 0;   // the devices' bound (render/instancing.h)
    double seconds_ = 0.0;                    // wall time of runs with several workers
    std::uint64_t scene_hash_without_camera_ = 0;  // scene/scene_hash.h
    std::string scene_hash_;                        // with the current camera
};

}  // namespace glslppm
