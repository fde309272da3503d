#include "render/memory_estimate.h"

#include <algorithm>

#include "render/density_estimator.h"
#include "render/gpu_layout.h"
#include "render/render_passes.h"
#include "render/scene_preparation.h"

namespace glslppm {

std::size_t PassStateBytes::total() const {
    return visible_points + pixel_stats + direct_light + film + pass_films + light_splats +
           photon_paths + photons + hash_cells + sorted_photons + rng_states + radius_stats;
}

PassStateBytes pass_state_bytes(const PassStateShape& s) {
    PassStateBytes b;
    const std::size_t px = s.pixels, ph = s.photon_threads;
    // Visible points, pixel statistics (2 vec4), direct light (2), film (1).
    b.visible_points = px * kVisiblePointVec4 * 16;
    b.pixel_stats = px * 2 * 16;
    b.direct_light = px * 2 * 16;
    b.film = px * 16;
    b.pass_films = px * s.pass_stride * 16;
    const std::size_t splat_bytes =
        s.light_tracing ? kLightSplatBytes * (1 + s.light_splat_groups) : 0;
    b.light_splats = px * splat_bytes;
    // Photon paths (3 vec4) and stored photons (3 vec4 each).
    const std::size_t stored = s.photon_slot * s.steps_per_gather;
    b.photon_paths = ph * kPhotonPathBytes;
    b.photons = stored * kPhotonBytes;
    b.hash_cells = s.hash_cells * 16;
    // The exact hash's sorted indices: every stored photon and a block sum per 1024 cells;
    // without it a one-uint placeholder stays bound.
    b.sorted_photons = (s.exact_hash ? stored + s.hash_cells / 1024 : 1) * 4;
    b.rng_states = s.paper_rng ? (px + ph) * 16 : 0;
    b.radius_stats = std::size_t(kRadiusStatsThreads) * 8;

    b.bytes_per_pixel = (kVisiblePointVec4 + 2 + 2 + 1) * 16 + s.pass_stride * 16 + splat_bytes;
    b.block_bytes_per_pixel =
        std::max({kVisiblePointVec4 * 16, s.pass_stride * 16, splat_bytes});
    b.bytes_per_photon =
        double(b.photon_paths + b.photons + b.hash_cells + (s.exact_hash ? b.sorted_photons : 0) +
               (s.paper_rng ? ph * 16 : 0)) /
        double(std::max<std::size_t>(ph, 1));
    b.largest_photon_buffer = std::max({b.photon_paths, b.photons, b.hash_cells, b.sorted_photons});
    return b;
}

std::uint32_t hash_cell_count(std::uint32_t photon_threads) {
    const std::uint64_t want = std::max<std::uint64_t>(2ull * photon_threads, 1024);
    std::uint64_t p = 1;
    while (p < want) p <<= 1;
    return static_cast<std::uint32_t>(p);
}

PassStateShape pass_state_shape(const RenderSettings& settings, const Scene* scene,
                                std::int64_t driver_largest) {
    PassStateShape s;
    s.pixels = std::size_t(settings.width) * std::size_t(settings.height);
    s.photon_threads = settings.photons_per_pass;
    s.hash_cells = hash_cell_count(settings.photons_per_pass);
    // Light groups add 4 vec4 (64 bytes) per group and pixel (docs/light_groups.md).
    const PassLayout layout =
        pass_layout(settings.passes, settings.direct_light == DirectLight::Photons,
                    scene ? static_cast<int>(scene->light_groups.size()) : 0);
    s.pass_stride = static_cast<std::size_t>(layout.stride);
    s.light_tracing =
        scene ? light_tracing_expected(*scene, settings)
              : settings.light_tracing && !layout.photon_split && !settings.full_variant;
    // VCM: its own light tracing technique splats, never the photons' (scene_features.cpp).
    if (settings.estimator == Estimator::Vcm)
        s.light_tracing = settings.vcm_techniques != VcmTechniques::PathTracing;
    // Light groups with light tracing: each group's splats too, 48 bytes a group and pixel.
    if (s.light_tracing) s.light_splat_groups = static_cast<std::size_t>(layout.light_groups);
    s.exact_hash = settings.hash == HashMode::Exact;
    s.paper_rng = settings.rng == RngKind::Paper;
    const DensityEstimator& estimator = density_estimator(settings.estimator);
    s.photon_slot = estimator.photon_slot(settings.photons_per_pass);
    s.steps_per_gather = estimator.photon_steps_per_gather(
        static_cast<std::uint32_t>(s.photon_slot), driver_largest, settings.max_bounces);
    if (const std::uint32_t slots = vcm_merge_slots(settings, driver_largest)) {
        s.photon_slot = settings.photons_per_pass;
        s.steps_per_gather = slots;
    }
    return s;
}

std::uint32_t vcm_merge_slots(const RenderSettings& settings, std::int64_t driver_largest) {
    if (settings.estimator != Estimator::Vcm || !vcm_merges(settings.vcm_techniques)) return 0;
    const std::size_t gib = std::size_t(1) << 30;
    const std::size_t cap =
        std::min(driver_largest > 0 ? static_cast<std::size_t>(driver_largest) : gib, gib);
    const std::size_t slot_bytes =
        std::max<std::size_t>(settings.photons_per_pass, 1) * kPhotonBytes;
    const std::size_t surfaces = static_cast<std::size_t>(std::max(settings.max_bounces, 0)) + 1;
    return static_cast<std::uint32_t>(std::clamp<std::size_t>(cap / slot_bytes, 1, surfaces));
}

}  // namespace glslppm
