// The pass-indexed radius schedule of probabilistic progressive photon mapping (Knaus and
// Zwicker 2011): pass i (1-based) uses r_i = r_1 s(i), independent of every other pass.
#pragma once

#include <cstdint>

namespace glslppm {

// s(i) for the 0-based pass index `pass` (i = pass + 1). Knaus and Zwicker's eq. 15,
// r_{i+1}^2 = r_i^2 (i + alpha) / (i + 1), in closed form:
//   s(i)^2 = prod_{k=1}^{i-1} (k + alpha) / (k + 1) = Gamma(i + alpha) / (Gamma(1 + alpha) Gamma(i + 1)).
// Accurate to 1e-9 (relative; a float radius holds 6e-8) for any index up to 2^53.
double pppm_radius_scale(std::uint64_t pass, double alpha);

// The radius of a pass: r_1 s(i), but never below `floor` (a radius already below the floor
// stays, as in SPPM's update).
float pppm_pass_radius(float initial_radius, float floor, std::uint64_t pass, double alpha);

}  // namespace glslppm
