#include "render/pppm_schedule.h"

#include <algorithm>
#include <cmath>

namespace glslppm {

double pppm_radius_scale(std::uint64_t pass, double alpha) {
    const double i = static_cast<double>(pass) + 1.0;
    double log_s2;
    if (i < 1e5) {
        // lgamma's values stay below 1.2e6 here: the difference keeps 3e-10.
        log_s2 = std::lgamma(i + alpha) - std::lgamma(i + 1.0) - std::lgamma(1.0 + alpha);
    } else {
        // Where the lgamma values would cancel: the asymptotic expansion
        // ln Gamma(z + a) - ln Gamma(z + b) = (a - b) ln z + (a - b)(a + b - 1) / (2z) + O(z^-2).
        log_s2 = (alpha - 1.0) * std::log(i) + (alpha - 1.0) * alpha / (2.0 * i) -
                 std::lgamma(1.0 + alpha);
    }
    return std::exp(0.5 * log_s2);
}

float pppm_pass_radius(float initial_radius, float floor, std::uint64_t pass, double alpha) {
    const double r = static_cast<double>(initial_radius) * pppm_radius_scale(pass, alpha);
    return std::max(static_cast<float>(r), std::min(initial_radius, floor));
}

}  // namespace glslppm
