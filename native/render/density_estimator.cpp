#include "render/density_estimator.h"

#include <algorithm>
#include <array>
#include <cstddef>

#include "render/gpu_layout.h"
#include "render/pppm_schedule.h"

namespace glslppm {
namespace {

constexpr std::array<DensityEstimator, 3> kEstimators = {{
    // Hachisuka and Jensen 2009, "Stochastic Progressive Photon Mapping".
    {.id = Estimator::Sppm,
     .name = "sppm",
     .title = "SPPM",
     .define = nullptr,
     .independent_passes = false,
     .photon_paths = PhotonPaths::AcrossPasses,
     .film = FilmResolve::FluxOverPixelRadius,
     .pass_radius_of = nullptr},
    // Knaus and Zwicker 2011, "Progressive Photon Mapping: A Probabilistic Approach".
    {.id = Estimator::Pppm,
     .name = "pppm",
     .title = "PPPM",
     .define = "ESTIMATOR_PPPM",
     .independent_passes = true,
     .photon_paths = PhotonPaths::WithinPass,
     .film = FilmResolve::MeanOfPasses,
     .pass_radius_of = &pppm_pass_radius},
    // Georgiev, Krivanek, Davidovic and Slusallek 2012, "Light Transport Simulation with
    // Vertex Connection and Merging" (docs/vcm.md): so far its path tracing technique, each
    // pass an eye path per pixel; the radius per pass is PPPM's, for its merging to come.
    {.id = Estimator::Vcm,
     .name = "vcm",
     .title = "VCM",
     .define = "ESTIMATOR_VCM",
     .independent_passes = true,
     .photon_paths = PhotonPaths::NoPhotons,
     .film = FilmResolve::MeanOfPasses,
     .pass_radius_of = &pppm_pass_radius},
}};

static_assert(kEstimators[std::size_t(Estimator::Sppm)].id == Estimator::Sppm);
static_assert(kEstimators[std::size_t(Estimator::Pppm)].id == Estimator::Pppm);
static_assert(kEstimators[std::size_t(Estimator::Vcm)].id == Estimator::Vcm);

}  // namespace

std::uint32_t DensityEstimator::photon_steps_per_pass(int max_bounces) const {
    if (photon_paths == PhotonPaths::NoPhotons) return 0;
    return photon_paths == PhotonPaths::WithinPass ? static_cast<std::uint32_t>(max_bounces) + 1u
                                                   : 1u;
}

std::uint32_t DensityEstimator::photon_slot(std::uint32_t photon_threads) const {
    return photon_paths == PhotonPaths::WithinPass ? (photon_threads + 15) / 16 * 16
                                                   : photon_threads;
}

std::uint32_t DensityEstimator::photon_steps_per_gather(std::uint32_t slot,
                                                        std::int64_t driver_largest,
                                                        int max_bounces) const {
    if (photon_paths != PhotonPaths::WithinPass) return 1;
    const std::size_t gib = std::size_t(1) << 30;
    const std::size_t cap =
        std::min(driver_largest > 0 ? static_cast<std::size_t>(driver_largest) : gib, gib);
    return static_cast<std::uint32_t>(
        std::clamp<std::size_t>(cap / (std::max<std::size_t>(slot, 1) * kPhotonBytes), 1,
                                photon_steps_per_pass(max_bounces)));
}

PassRadius DensityEstimator::pass_radius(float initial_radius, float floor, std::uint64_t pass,
                                         double alpha, std::uint32_t photon_threads) const {
    PassRadius p;
    p.radius = pass_radius_of(initial_radius, floor, pass, alpha);
    const double r = p.radius;
    p.scale = static_cast<float>(1.0 / (3.14159265358979323846 * r * r * double(photon_threads)));
    return p;
}

std::span<const DensityEstimator> density_estimators() { return kEstimators; }

const DensityEstimator& density_estimator(Estimator estimator) {
    return kEstimators[static_cast<std::size_t>(estimator)];
}

const DensityEstimator* find_density_estimator(const std::string& name) {
    for (const DensityEstimator& e : kEstimators)
        if (name == e.name) return &e;
    return nullptr;
}

std::string independent_estimator_names() {
    std::string names;
    for (const DensityEstimator& e : kEstimators)
        if (e.independent_passes) names += (names.empty() ? "" : " or ") + std::string(e.name);
    return names;
}

}  // namespace glslppm
