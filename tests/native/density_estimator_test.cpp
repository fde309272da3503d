// The density estimators' descriptions (render/density_estimator.h): what each decides,
// as numbers. SPPM: one photon step a pass, each pixel its own radius; PPPM: whole paths in
// max_bounces + 1 steps stored in 16-aligned slots, and pass i's radius r_1 s(i) with its
// estimate's factor 1 / (pi r^2 N_emitted) (Knaus and Zwicker 2011, eq. 15).
#include "render/density_estimator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>
#include <string>

namespace glslppm {
namespace {

constexpr double kPi = std::numbers::pi;

const DensityEstimator& sppm() { return density_estimator(Estimator::Sppm); }
const DensityEstimator& pppm() { return density_estimator(Estimator::Pppm); }
const DensityEstimator& vcm() { return density_estimator(Estimator::Vcm); }

TEST(DensityEstimator, EveryEstimatorHasItsRowAndName) {
    ASSERT_EQ(density_estimators().size(), 3u);
    for (const DensityEstimator& e : density_estimators()) {
        EXPECT_EQ(&density_estimator(e.id), &e);
        EXPECT_EQ(find_density_estimator(e.name), &e);
        EXPECT_EQ(parse_estimator(e.name), e.id);
        EXPECT_EQ(to_string(e.id), e.name);
    }
    EXPECT_STREQ(sppm().name, "sppm");
    EXPECT_STREQ(pppm().name, "pppm");
    EXPECT_EQ(sppm().define, nullptr);  // the shaders' default
    EXPECT_STREQ(pppm().define, "ESTIMATOR_PPPM");
    EXPECT_STREQ(vcm().name, "vcm");
    EXPECT_STREQ(vcm().define, "ESTIMATOR_VCM");
    EXPECT_EQ(find_density_estimator("ppm"), nullptr);
    try {
        parse_estimator("ppm");
        FAIL() << "parse_estimator accepted 'ppm'";
    } catch (const std::invalid_argument& e) {
        EXPECT_STREQ(e.what(), "estimator: 'ppm' is not an estimator (sppm, pppm, vcm)");
    }
}

TEST(DensityEstimator, SettingsNameWhatVcmDoesNotSupportYet) {
    RenderSettings s;
    s.estimator = Estimator::Vcm;
    EXPECT_NO_THROW(validate(s));
    s.direct_light = DirectLight::Photons;
    EXPECT_THROW(validate(s), std::invalid_argument);
    s.direct_light = DirectLight::Sampled;
    s.passes = {RenderPass::Depth, RenderPass::Normal, RenderPass::Emission,
                RenderPass::Environment, RenderPass::DenoisingNormal, RenderPass::DenoisingAlbedo};
    EXPECT_NO_THROW(validate(s));  // its data passes, Emission and Environment
    s.passes.push_back(RenderPass::Caustics);
    try {
        validate(s);
        FAIL() << "VCM with the light split's passes";
    } catch (const std::invalid_argument& e) {
        EXPECT_STREQ(e.what(), "estimator vcm: render pass 'caustics' (the light split: direct, "
                               "indirect, caustics) is not supported yet");
    }
}

TEST(DensityEstimator, PppmsAndVcmsPassesAreIndependent) {
    EXPECT_FALSE(sppm().independent_passes);
    EXPECT_TRUE(pppm().independent_passes);
    EXPECT_TRUE(vcm().independent_passes);
    EXPECT_EQ(independent_estimator_names(), "pppm or vcm");
    EXPECT_EQ(vcm().film, FilmResolve::MeanOfPasses);
    EXPECT_EQ(vcm().pass_radius_of, pppm().pass_radius_of);  // PPPM's radius, for merging
    EXPECT_EQ(sppm().film, FilmResolve::FluxOverPixelRadius);
    EXPECT_EQ(pppm().film, FilmResolve::MeanOfPasses);
    EXPECT_EQ(sppm().pass_radius_of, nullptr);  // each pixel its own radius
    EXPECT_NE(pppm().pass_radius_of, nullptr);
}

TEST(DensityEstimator, PhotonStepsAPass) {
    EXPECT_EQ(sppm().photon_paths, PhotonPaths::AcrossPasses);
    EXPECT_EQ(pppm().photon_paths, PhotonPaths::WithinPass);
    EXPECT_EQ(sppm().photon_steps_per_pass(9), 1u);
    EXPECT_EQ(sppm().photon_steps_per_pass(0), 1u);
    EXPECT_EQ(pppm().photon_steps_per_pass(9), 10u);  // a photon may land a 10th time
    EXPECT_EQ(pppm().photon_steps_per_pass(0), 1u);
    // VCM's passes are eye paths alone so far (docs/vcm.md): no photon step runs.
    EXPECT_EQ(vcm().photon_paths, PhotonPaths::NoPhotons);
    EXPECT_EQ(vcm().photon_steps_per_pass(9), 0u);
}

TEST(DensityEstimator, PhotonSlotsAndStepsPerGather) {
    EXPECT_EQ(sppm().photon_slot(1000), 1000u);
    EXPECT_EQ(pppm().photon_slot(1000), 1008u);  // rounded up to 16
    EXPECT_EQ(pppm().photon_slot(1024), 1024u);
    EXPECT_EQ(pppm().photon_slot(1), 16u);
    EXPECT_EQ(sppm().photon_steps_per_gather(1000, 0, 9), 1u);
    EXPECT_EQ(sppm().photon_steps_per_gather(1000, 1, 9), 1u);
    // 48 bytes a photon: 1 GiB holds every step of 1008 photons, at most max_bounces + 1.
    EXPECT_EQ(pppm().photon_steps_per_gather(1008, 0, 9), 10u);
    EXPECT_EQ(pppm().photon_steps_per_gather(1008, 0, 2), 3u);
    EXPECT_EQ(pppm().photon_steps_per_gather(1008, 3 * 1008 * 48, 9), 3u);
    EXPECT_EQ(pppm().photon_steps_per_gather(1008, 3 * 1008 * 48 - 1, 9), 2u);
    EXPECT_EQ(pppm().photon_steps_per_gather(1008, 16, 9), 1u);  // one step even past the limit
    // 2^22 photons a step, 192 MiB: 5 in 1 GiB, which also caps a larger driver limit.
    EXPECT_EQ(pppm().photon_steps_per_gather(1u << 22, 0, 9), 5u);
    EXPECT_EQ(pppm().photon_steps_per_gather(1u << 22, std::int64_t(4) << 30, 9), 5u);
}

TEST(DensityEstimator, PppmsPassRadiusAndScale) {
    const float r1 = 0.1f, floor = 1e-4f;
    const double alpha = 0.7;
    const std::uint32_t photons = 1000;
    // s(i)^2 = prod_{k=1}^{i-1} (k + alpha) / (k + 1): 1, 0.85, 0.85 * 2.7 / 3 = 0.765.
    const double s2[3] = {1.0, 0.85, 0.765};
    for (std::uint64_t pass = 0; pass < 3; ++pass) {
        const PassRadius p = pppm().pass_radius(r1, floor, pass, alpha, photons);
        const double r = 0.1 * std::sqrt(s2[pass]);
        EXPECT_NEAR(p.radius, r, 1e-7 * r) << "pass " << pass;
        const double scale = 1.0 / (kPi * double(p.radius) * double(p.radius) * photons);
        EXPECT_EQ(p.scale, static_cast<float>(scale)) << "pass " << pass;
        EXPECT_NEAR(p.scale, 1.0 / (kPi * r * r * photons), 1e-6 / (kPi * r * r * photons));
    }
    EXPECT_EQ(pppm().pass_radius(r1, floor, 0, alpha, photons).radius, 0.1f);
    EXPECT_NEAR(pppm().pass_radius(r1, floor, 0, alpha, photons).scale, 0.031830989, 1e-8);
    // Far along, the radius stops at the floor (and the scale follows it).
    const PassRadius late = pppm().pass_radius(r1, 1e-3f, std::uint64_t(1) << 40, 0.1, photons);
    EXPECT_EQ(late.radius, 1e-3f);
    EXPECT_NEAR(late.scale, 1.0 / (kPi * 1e-6 * photons), 1e-3);
}

TEST(DensityEstimator, SettingsRefuseWhatPassesThatDependOnEachOtherCannotDo) {
    RenderSettings s;
    s.estimator = Estimator::Pppm;
    s.rng = RngKind::Paper;
    EXPECT_THROW(validate(s), std::invalid_argument);
    s.rng = RngKind::Pcg;
    s.devices = {0, 1};
    s.first_pass = 7;
    EXPECT_NO_THROW(validate(s));
    s.estimator = Estimator::Sppm;
    try {
        validate(s);
        FAIL() << "SPPM on two devices";
    } catch (const std::invalid_argument& e) {
        EXPECT_STREQ(e.what(),
                     "devices: several devices need estimator pppm or vcm (SPPM's passes depend on each "
                     "other and cannot be split)");
    }
    s.devices = {};
    try {
        validate(s);
        FAIL() << "SPPM from pass 7";
    } catch (const std::invalid_argument& e) {
        EXPECT_STREQ(e.what(), "first_pass: only estimator pppm or vcm can start at a pass "
                               "other than 0");
    }
}

}  // namespace
}  // namespace glslppm
