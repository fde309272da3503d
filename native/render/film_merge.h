// Films that are means over disjoint sets of PPPM passes merge into the mean over their union
// exactly (up to float rounding): weight each by its pass count.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

namespace glslppm {

// sum_k passes[k] * films[k] / sum_k passes[k], every channel, summed in double. Films with 0
// passes are left out; all of them must have the same size (std::invalid_argument otherwise).
// When every count is 0, the first film is returned as it is.
std::vector<float> merge_films(const std::vector<const std::vector<float>*>& films,
                               const std::vector<std::uint64_t>& passes);

// Sorted pass indices as half-open ranges [first, end): 0 1 2 5 6 -> [0, 3) [5, 7).
std::vector<std::pair<std::uint64_t, std::uint64_t>> pass_ranges(std::vector<std::uint64_t> indices);

}  // namespace glslppm
