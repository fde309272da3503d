// The samplers of issue 31's media, run on the real driver through the test program
// shaders/tests/media_probe.comp.
// The Henyey-Greenstein phase function (shaders/common/phase.glsl):
// - sampling matches the density: a chi-squared test over (cos theta, azimuth) bins of the
//   sampled directions against the closed-form distribution of cos theta and a uniform
//   azimuth, at g = -0.7, 0, 0.3 and 0.9;
// - the density the sampler returns is the closed form at the sampled cosine;
// - the density integrates to 1 over the sphere.
// Equiangular sampling of a distance towards a light point (shaders/common/equiangular.glsl):
// the same three checks over distance bins, for a light near the ray and far from it, with
// the segment around its foot and beside it.
// Measured (llvmpipe): the chi-squared p-values 0.22 to 0.98 against thresholds of 2.5e-3
// and 3.3e-3; the returned densities within 3.5e-5 of the closed form (bound 2e-3); the
// integrals 1.000000 to 1.000001 (bound 1e-4). A density 1% off fails the integral by 100
// times its bound. Planted errors, not kept: a sign error in the phase function's inverse
// gave chi2 6e5 to 3e8; the light's foot moved by 0.01 put the density 22% off.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "chi_squared.h"
#include "gl/shader_program.h"
#include "gl_probe.h"

namespace glslppm {
namespace {

using gl::ComputeProgram;
using gl_probe::Buffers;
using gl_probe::gl_thread;

constexpr double kPi = 3.14159265358979323846;
const float kAnisotropies[] = {-0.7f, 0.0f, 0.3f, 0.9f};
// The arrival direction: tilted off every axis, so the sampler's frame is a general one.
const glm::vec3 kArrived = glm::normalize(glm::vec3(0.2f, -0.4f, 0.9f));

// The equiangular sampler's ray segment and light point.
struct Segment {
    glm::vec3 o, d, c;
    float t0, t1;
};

// One dispatch of the probe: mode 0 draws `count` directions (xyz, density), mode 1
// evaluates the phase function at the cosines in `in` (x); modes 2 and 3 the same for the
// equiangular distance on `segment` (t, density).
std::vector<glm::vec4> probe(std::uint32_t mode, float g, std::uint32_t count,
                             const std::vector<glm::vec4>& in = {}, const Segment& segment = {}) {
    const std::vector<glm::vec4>& cosines = in;
    std::vector<glm::vec4> out;
    gl_thread().call([&] {
        static ComputeProgram program("tests/media_probe.comp", {});
        Buffers buffers({{20, cosines.empty() ? nullptr : cosines.data(), cosines.size() * 16},
                         {21, nullptr, std::size_t(count) * 16}});
        program.use();
        glUniform1ui(program.uniform("u_mode"), mode);
        glUniform1ui(program.uniform("u_count"), count);
        glUniform1f(program.uniform("u_g"), g);
        glUniform3f(program.uniform("u_arrived"), kArrived.x, kArrived.y, kArrived.z);
        glUniform1ui(program.uniform("u_seed"), 17u);
        glUniform3f(program.uniform("u_o"), segment.o.x, segment.o.y, segment.o.z);
        glUniform3f(program.uniform("u_d"), segment.d.x, segment.d.y, segment.d.z);
        glUniform3f(program.uniform("u_c"), segment.c.x, segment.c.y, segment.c.z);
        glUniform1f(program.uniform("u_t0"), segment.t0);
        glUniform1f(program.uniform("u_t1"), segment.t1);
        gl_probe::dispatch_items(count);
        out = buffers.read<glm::vec4>(1, count);
    });
    return out;
}

double hg(double c, double g) {
    const double d = 1.0 + g * g - 2.0 * g * c;
    return (1.0 - g * g) / (4.0 * kPi * d * std::sqrt(d));
}

// P(cos theta <= c), the closed form phase.glsl inverts.
double hg_cdf(double c, double g) {
    if (std::abs(g) < 1e-3) return 0.5 * (c + 1.0);
    return (1.0 - g * g) / (2.0 * g) * (1.0 / std::sqrt(1.0 + g * g - 2.0 * g * c) - 1.0 / (1.0 + g));
}

TEST(MediaProbe, HenyeyGreensteinSamplingMatchesItsDistribution) {
    constexpr std::uint32_t kCount = 400000;
    constexpr int kCosBins = 40, kPhiBins = 24;
    // A frame about the arrival direction for the azimuth (any frame: it is uniform).
    const glm::dvec3 a(kArrived);
    const glm::dvec3 t = glm::normalize(glm::cross(a, glm::dvec3(1.0, 0.0, 0.0)));
    const glm::dvec3 b = glm::cross(a, t);
    for (float g : kAnisotropies) {
        const std::vector<glm::vec4> samples = probe(0, g, kCount);
        std::vector<double> observed(kCosBins * kPhiBins, 0.0);
        double worst_density = 0.0;
        for (const glm::vec4& s : samples) {
            const glm::dvec3 d(s.x, s.y, s.z);
            const double c = std::clamp(glm::dot(a, d), -1.0, 1.0);
            double phi = std::atan2(glm::dot(b, d), glm::dot(t, d));
            if (phi < 0.0) phi += 2.0 * kPi;
            const int i = std::min(kCosBins - 1, int((c + 1.0) * 0.5 * kCosBins));
            const int j = std::min(kPhiBins - 1, int(phi / (2.0 * kPi) * kPhiBins));
            observed[i * kPhiBins + j] += 1.0;
            worst_density = std::max(worst_density, std::abs(s.w / hg(c, g) - 1.0));
        }
        // Bins of the same cos range share their expected count; bins expecting fewer than 5
        // are pooled (Mitsuba's rule), as g = 0.9 leaves the backward ones nearly empty.
        double chi2 = 0.0, pooled_observed = 0.0, pooled_expected = 0.0;
        int bins = 0;
        for (int i = 0; i < kCosBins; ++i) {
            const double lo = -1.0 + 2.0 * i / kCosBins, hi = -1.0 + 2.0 * (i + 1) / kCosBins;
            const double expected = kCount * (hg_cdf(hi, g) - hg_cdf(lo, g)) / kPhiBins;
            for (int j = 0; j < kPhiBins; ++j) {
                const double o = observed[i * kPhiBins + j];
                if (expected < 5.0) {
                    pooled_observed += o;
                    pooled_expected += expected;
                } else {
                    chi2 += (o - expected) * (o - expected) / expected;
                    ++bins;
                }
            }
        }
        if (pooled_expected >= 5.0) {
            chi2 += (pooled_observed - pooled_expected) * (pooled_observed - pooled_expected) /
                    pooled_expected;
            ++bins;
        }
        const int dof = bins - 1;
        const double p = chi_squared::gamma_q(0.5 * dof, 0.5 * chi2);
        std::printf("  g %+.1f: chi2 %.1f / %d dof, p = %.4f; density vs closed form %.2g\n",
                    g, chi2, dof, p, worst_density);
        // Four tests at 1% overall (Sidak): 1 - 0.99^(1/4) each.
        EXPECT_GT(p, 2.5e-3) << "g " << g;
        // The returned density is the closed form at the sample's float cosine.
        EXPECT_LT(worst_density, 2e-3) << "g " << g;
    }
}

TEST(MediaProbe, HenyeyGreensteinIntegratesToOne) {
    // 2 pi times the integral over cos theta of the density, midpoint rule on 2^16 cells:
    // its error is below 1e-6 even for g = 0.9's peak of 15 per steradian.
    constexpr std::uint32_t kCells = 1u << 16;
    std::vector<glm::vec4> cosines(kCells);
    for (std::uint32_t k = 0; k < kCells; ++k)
        cosines[k] = glm::vec4(float(-1.0 + (k + 0.5) * 2.0 / kCells), 0.0f, 0.0f, 0.0f);
    for (float g : kAnisotropies) {
        const std::vector<glm::vec4> density = probe(1, g, kCells, cosines);
        double integral = 0.0;
        for (const glm::vec4& v : density) integral += v.x;
        integral *= 2.0 * kPi * 2.0 / kCells;
        std::printf("  g %+.1f: integral %.6f\n", g, integral);
        EXPECT_NEAR(integral, 1.0, 1e-4) << "g " << g;
    }
}

// Segments of the ray from o along d with the light point h off the ray at its foot t_c.
Segment segment(double h, double t_c, float t0, float t1) {
    const glm::vec3 o(0.1f, -0.2f, 0.3f), d = glm::normalize(glm::vec3(1.0f, 0.5f, -0.2f));
    const glm::vec3 side = glm::normalize(glm::cross(d, glm::vec3(0.0f, 0.0f, 1.0f)));
    return {o, d, o + float(t_c) * d + float(h) * side, t0, t1};
}

struct SegmentCase {
    double h, t_c;
    float t0, t1;
};
// A light close to the ray (a sharp peak at its foot), one far from it, and a segment that
// ends before the foot.
const SegmentCase kSegments[] = {{0.05, 2.0, 0.0f, 5.0f}, {1.0, 2.0, 0.0f, 5.0f},
                                 {0.3, 6.0, 0.5f, 4.0f}};

TEST(MediaProbe, EquiangularSamplingMatchesItsDistribution) {
    constexpr std::uint32_t kCount = 400000;
    constexpr int kBins = 60;
    for (const SegmentCase& k : kSegments) {
        const Segment seg = segment(k.h, k.t_c, k.t0, k.t1);
        // The closed form in double, from the float inputs as the shader sees them.
        const glm::dvec3 o(seg.o), d(seg.d), c(seg.c);
        const double t_c = glm::dot(c - o, d), h = glm::length(c - (o + t_c * d));
        const double a0 = std::atan2(seg.t0 - t_c, h), a1 = std::atan2(seg.t1 - t_c, h);
        auto cdf = [&](double t) { return (std::atan2(t - t_c, h) - a0) / (a1 - a0); };
        auto pdf = [&](double t) { return h / ((a1 - a0) * (h * h + (t - t_c) * (t - t_c))); };
        const std::vector<glm::vec4> samples = probe(2, 0.0f, kCount, {}, seg);
        std::vector<double> observed(kBins, 0.0);
        double worst_density = 0.0;
        int outside = 0;
        const double width = (double(seg.t1) - seg.t0) / kBins;
        for (const glm::vec4& s : samples) {
            if (s.x < seg.t0 || s.x > seg.t1) ++outside;
            const int i = std::clamp(int((s.x - seg.t0) / width), 0, kBins - 1);
            observed[i] += 1.0;
            worst_density = std::max(worst_density, std::abs(s.y / pdf(s.x) - 1.0));
        }
        double chi2 = 0.0;
        int bins = 0;
        for (int i = 0; i < kBins; ++i) {
            const double expected =
                kCount * (cdf(seg.t0 + (i + 1) * width) - cdf(seg.t0 + i * width));
            if (expected < 5.0) continue;  // none here: the smallest bin expects hundreds
            chi2 += (observed[i] - expected) * (observed[i] - expected) / expected;
            ++bins;
        }
        const double p = chi_squared::gamma_q(0.5 * (bins - 1), 0.5 * chi2);
        std::printf("  h %.2f, foot %.1f, [%.1f, %.1f]: chi2 %.1f / %d dof, p = %.4f; density "
                    "vs closed form %.2g\n", k.h, k.t_c, k.t0, k.t1, chi2, bins - 1, p,
                    worst_density);
        EXPECT_EQ(outside, 0);
        // Three tests at 1% overall (Sidak): 1 - 0.99^(1/3) each.
        EXPECT_GT(p, 3.3e-3) << "h " << k.h;
        EXPECT_LT(worst_density, 2e-3) << "h " << k.h;
    }
}

TEST(MediaProbe, EquiangularDensityIntegratesToOne) {
    constexpr std::uint32_t kCells = 1u << 16;
    for (const SegmentCase& k : kSegments) {
        const Segment seg = segment(k.h, k.t_c, k.t0, k.t1);
        const double width = (double(seg.t1) - seg.t0) / kCells;
        std::vector<glm::vec4> ts(kCells);
        for (std::uint32_t i = 0; i < kCells; ++i)
            ts[i] = glm::vec4(float(seg.t0 + (i + 0.5) * width), 0.0f, 0.0f, 0.0f);
        double integral = 0.0;
        for (const glm::vec4& v : probe(3, 0.0f, kCells, ts, seg)) integral += v.y;
        integral *= width;
        std::printf("  h %.2f: integral %.6f\n", k.h, integral);
        EXPECT_NEAR(integral, 1.0, 1e-4) << "h " << k.h;
    }
}

}  // namespace
}  // namespace glslppm
