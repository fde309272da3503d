// PPPM's pass-indexed radius (render/pppm_schedule.h) against Knaus and Zwicker's recurrence
// r_{i+1}^2 = r_i^2 (i + alpha) / (i + 1), multiplied out pass by pass in long double.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "render/pppm_schedule.h"

namespace glslppm {
namespace {

TEST(PppmSchedule, FirstPassesAreTheRecurrence) {
    for (double alpha : {0.1, 0.5, 0.7, 1.0}) {
        long double s2 = 1.0L;
        for (std::uint64_t pass = 0; pass < 200000; ++pass) {
            const double s = pppm_radius_scale(pass, alpha);
            // lgamma's rounding at 1e5 is 3e-10 (relative); an index off by one changes s by
            // (1 - alpha) / (2i) > 1e-6 here, a wrong exponent by far more.
            ASSERT_NEAR(s, std::sqrt(static_cast<double>(s2)), 1e-9 * std::sqrt(double(s2)))
                << "alpha " << alpha << " pass " << pass;
            const long double i = static_cast<long double>(pass) + 1.0L;
            s2 *= (i + alpha) / (i + 1.0L);
        }
    }
}

TEST(PppmSchedule, LargeIndicesFollowThePowerLaw) {
    // s(i)^2 -> i^(alpha - 1) / Gamma(1 + alpha): checked at 2^52, where a difference of
    // lgamma values would have lost every digit.
    const double alpha = 0.7;
    const double i = std::ldexp(1.0, 52);
    const double expected = std::sqrt(std::pow(i, alpha - 1.0) / std::tgamma(1.0 + alpha));
    EXPECT_NEAR(pppm_radius_scale(std::uint64_t(1) << 52, alpha) / expected, 1.0, 1e-12);
    // Smaller every pass, also across the switch to the asymptotic form at 1e5.
    for (std::uint64_t pass = 99990; pass < 100010; ++pass)
        EXPECT_LT(pppm_radius_scale(pass + 1, alpha), pppm_radius_scale(pass, alpha));
    EXPECT_EQ(pppm_radius_scale(0, alpha), 1.0);
    EXPECT_EQ(pppm_radius_scale(123, 1.0), 1.0);  // alpha = 1: the radius never shrinks
}

TEST(PppmSchedule, RadiusStopsAtTheFloor) {
    EXPECT_EQ(pppm_pass_radius(0.1f, 1e-3f, 0, 0.7), 0.1f);
    EXPECT_EQ(pppm_pass_radius(0.1f, 1e-3f, std::uint64_t(1) << 40, 0.1), 1e-3f);
    // A radius already below the floor stays as it is.
    EXPECT_EQ(pppm_pass_radius(1e-4f, 1e-3f, 1000, 0.7), 1e-4f);
}

}  // namespace
}  // namespace glslppm
