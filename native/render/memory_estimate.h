// The GPU bytes of a render's pass state (the per-pixel and per-photon buffers), their one
// owner: allocate_pass_state (renderer_setup.cpp) allocates these sizes, plan_tiles
// (tiled_render.cpp) splits a frame by them, and the add-on's refusal
// (addon/engine/memory.py) asks for them through the module's memory_estimate before
// anything is allocated. The scene's own buffers (BVH, materials, emitters, images) are not
// counted: they do not grow with the resolution or the photons per pass.
#pragma once

#include <cstddef>
#include <cstdint>

#include "render/settings.h"
#include "scene/scene.h"

namespace glslppm {

// What the pass state's sizes depend on.
struct PassStateShape {
    std::size_t pixels = 0, photon_threads = 0, hash_cells = 0;
    std::size_t pass_stride = 0;  // vec4s a pixel of the render passes' films (PassLayout)
    bool light_tracing = false;   // light tracing's splats (kLightSplatBytes a pixel)
    // With light groups, a block of splats per group after the frame's (light_splats.glsl).
    std::size_t light_splat_groups = 0;
    bool exact_hash = false;      // the exact hash's sorted photon indices
    bool paper_rng = false;       // a generator state per pixel and per photon thread
    // The stored photons: photon_slot each step, steps_per_gather steps (the estimator's:
    // render/density_estimator.h; PPPM stores several steps side by side, SPPM one step of
    // photon_threads).
    std::size_t photon_slot = 0, steps_per_gather = 1;
};

// Bytes of each pass-state buffer, as allocate_pass_state makes them.
struct PassStateBytes {
    // Per pixel.
    std::size_t visible_points = 0, pixel_stats = 0, direct_light = 0, film = 0;
    std::size_t pass_films = 0, light_splats = 0;
    // Per photon thread (hash cells: the next power of two of twice the photons).
    std::size_t photon_paths = 0, photons = 0, hash_cells = 0, sorted_photons = 0;
    std::size_t rng_states = 0;    // pixels and photon threads (RngKind::Paper)
    std::size_t radius_stats = 0;  // kRadiusStatsThreads (sum, max) pairs

    std::size_t total() const;
    std::size_t bytes_per_pixel = 0;        // the per-pixel buffers, for one pixel
    std::size_t block_bytes_per_pixel = 0;  // the largest per-pixel buffer, for one pixel
    double bytes_per_photon = 0.0;          // the per-photon buffers, for one photon thread
    std::size_t largest_photon_buffer = 0;  // the largest buffer that tiles do not split
};

PassStateBytes pass_state_bytes(const PassStateShape& shape);

// The photon hash's cells: the next power of two of twice the photons, at least 1024.
std::uint32_t hash_cell_count(std::uint32_t photon_threads);

// The pass state of a render of `settings` on a device whose largest storage buffer is
// `driver_largest` (0: unknown). `scene` decides light tracing's splats as scene
// preparation does (render/scene_features.cpp); without one (the add-on asks before it
// exports) they are counted wherever the settings allow light tracing. A scene whose
// only mirror or glass material no triangle uses is counted with the splats too.
PassStateShape pass_state_shape(const RenderSettings& settings, const Scene* scene,
                                std::int64_t driver_largest);

// VCM's vertex merging (docs/vcm.md): how many of a light path's rough vertices a pass stores,
// in slots of photon_threads photons, one slot for each (the k-th vertex of path i is photon
// k photon_threads + i): one per surface a path may meet (max_bounces + 1), as many as one
// storage buffer of at most 1 GiB and the driver's largest (driver_largest; 0: unknown) holds.
// 0 where VCM does not merge. A path's vertices past that many are not merged (the eye paths
// weigh their light to path tracing alone: common/vcm_merging.glsl).
std::uint32_t vcm_merge_slots(const RenderSettings& settings, std::int64_t driver_largest);

}  // namespace glslppm
