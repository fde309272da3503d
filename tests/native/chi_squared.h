// Goodness-of-fit statistics the probe tests share (bsdf_probe_test.cpp, phase_probe_test.cpp).
#pragma once

#include <cmath>

namespace glslppm::chi_squared {

// The regularised upper incomplete gamma Q(a, x), by its series (x < a + 1) or its
// continued fraction (Lentz's method): the p-value of a chi-squared statistic x with 2a
// degrees of freedom.
inline double gamma_q(double a, double x) {
    if (x <= 0.0) return 1.0;
    const double log_prefix = a * std::log(x) - x - std::lgamma(a);
    if (x < a + 1.0) {
        double term = 1.0 / a, sum = term;
        for (int n = 1; n < 1000; ++n) {
            term *= x / (a + n);
            sum += term;
            if (std::abs(term) < std::abs(sum) * 1e-15) break;
        }
        return 1.0 - sum * std::exp(log_prefix);
    }
    double b = x + 1.0 - a, c = 1e300, d = 1.0 / b, h = d;
    for (int n = 1; n < 1000; ++n) {
        const double an = -n * (n - a);
        b += 2.0;
        d = an * d + b;
        if (std::abs(d) < 1e-300) d = 1e-300;
        c = b + an / c;
        if (std::abs(c) < 1e-300) c = 1e-300;
        d = 1.0 / d;
        const double delta = d * c;
        h *= delta;
        if (std::abs(delta - 1.0) < 1e-15) break;
    }
    return std::exp(log_prefix) * h;
}

}  // namespace glslppm::chi_squared
