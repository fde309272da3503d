// How a render's passes become an image: the density estimators, one description each
// (RenderSettings::estimator chooses one). SPPM (Hachisuka and Jensen 2009) shrinks each
// pixel's radius from its own photon count, so pass k+1 continues pass k; PPPM (Knaus and
// Zwicker 2011) gives pass i the radius r_1 s(i) and its own estimate, so the image is the
// mean of independent passes.
//
// Every decision in which the estimators differ is a field of the description, and the code
// asks it instead of naming an estimator: the pass loop (pass_stages.cpp), the runs
// (renderer.cpp), the film and stats read back (renderer_readback.cpp), the photon buffer's
// size (memory_estimate.cpp, renderer_setup.cpp), the settings' checks (settings.cpp), the
// programs' define (scene_features.cpp) and the farm merge (farm_merge.cpp). A new
// estimator is a row of density_estimator.cpp (and, if its shaders differ, the code under
// its define).
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include "render/settings.h"

namespace glslppm {

// Where a pass's photon paths begin and end.
enum class PhotonPaths {
    // Each pass traces one bounce of every path; a path goes on in the next pass from its
    // state in the photon path buffer, and a new one starts where one ended (N_emitted counts
    // the paths started). One photon step a pass, hashed and gathered.
    AcrossPasses,
    // Each pass starts every path and traces it whole, in max_bounces + 1 photon steps
    // (a photon may land a (max_bounces + 1)th time: common/bounces.glsl). The steps are
    // stored side by side in slots of one buffer and hashed and gathered together, as many
    // as fit (photon_steps_per_gather).
    WithinPass,
    // No photon paths (VCM's path tracing technique, docs/vcm.md): the pass is its eye
    // paths alone, nothing hashed or gathered.
    NoPhotons,
};

// What the film's photon light is (resolve_film.comp, resolve_render_pass).
enum class FilmResolve {
    // Each pixel's flux over its own radius and the paths started, tau / (pi R^2 N_emitted)
    // (Hachisuka and Jensen 2009): reads the pixel statistics' radius.
    FluxOverPixelRadius,
    // The mean of the passes' own estimates, each scaled in its pass (gather.comp): tau / passes.
    MeanOfPasses,
};

// A pass's frame constants where every pixel gathers with the pass's radius (FrameBlock's
// pass_radius and pass_scale).
struct PassRadius {
    float radius = 0.0f;
    float scale = 0.0f;  // the pass estimate's factor 1 / (pi r^2 N_emitted)
};

struct DensityEstimator {
    Estimator id;
    const char* name;   // RenderSettings, the CLI's --estimator, the farm's glslppm.estimator
    const char* title;  // in messages: "SPPM's passes depend on each other"
    // The programs' #define (the variant's name gets "estimator=<name>"); nullptr: none,
    // the shaders' default (SPPM).
    const char* define;
    // A pass is a function of (seed, its index) alone: passes run in any order, from any
    // settings.first_pass, on several devices at once or on farm machines, and their films
    // merge exactly (film_merge.h, farm_merge.h). The paper's generator, which carries its
    // state from pass to pass, cannot serve them. Otherwise passes run in order on one device.
    bool independent_passes;
    PhotonPaths photon_paths;
    FilmResolve film;
    // The radius every pixel gathers with in pass `pass` (0-based), at least `floor`;
    // nullptr: each pixel its own radius (the visible points' statistics).
    float (*pass_radius_of)(float initial_radius, float floor, std::uint64_t pass, double alpha);

    // Photon steps a pass: 1 (PhotonPaths::AcrossPasses) or max_bounces + 1 (WithinPass).
    std::uint32_t photon_steps_per_pass(int max_bounces) const;
    // Photons a step's slot of the photon buffer holds: photon_threads, rounded up to 16
    // (the storage buffer offset alignment) where the steps of a pass are stored side by
    // side; the padding stays zero, "not stored".
    std::uint32_t photon_slot(std::uint32_t photon_threads) const;
    // The photon steps stored side by side before one hash and gather: as many slots as one
    // storage buffer of at most 1 GiB (and at most the driver's largest, driver_largest; 0:
    // unknown) holds, at most photon_steps_per_pass.
    std::uint32_t photon_steps_per_gather(std::uint32_t slot, std::int64_t driver_largest,
                                          int max_bounces) const;
    // Pass `pass`'s radius and its estimate's factor, where pass_radius_of is set: every
    // photon thread starts one path per pass, so N_emitted is photon_threads.
    PassRadius pass_radius(float initial_radius, float floor, std::uint64_t pass, double alpha,
                           std::uint32_t photon_threads) const;
};

// Every estimator, in the order of the Estimator enum.
std::span<const DensityEstimator> density_estimators();
const DensityEstimator& density_estimator(Estimator estimator);
// By name ("sppm", "pppm"); nullptr for none.
const DensityEstimator* find_density_estimator(const std::string& name);
// The names of the estimators with independent passes, for messages: "pppm".
std::string independent_estimator_names();

}  // namespace glslppm
