#include "render/film_merge.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace glslppm {

std::vector<float> merge_films(const std::vector<const std::vector<float>*>& films,
                               const std::vector<std::uint64_t>& passes) {
    if (films.empty() || films.size() != passes.size())
        throw std::invalid_argument("merge_films: one pass count per film is needed");
    for (std::size_t k = 1; k < films.size(); ++k)
        if (films[k]->size() != films[0]->size())
            throw std::invalid_argument("merge_films: film " + std::to_string(k) + " has " +
                                        std::to_string(films[k]->size()) + " values, film 0 " +
                                        std::to_string(films[0]->size()));
    double total = 0.0;
    for (std::uint64_t n : passes) total += static_cast<double>(n);
    if (total == 0.0) return *films[0];
    std::vector<double> sum(films[0]->size(), 0.0);
    for (std::size_t k = 0; k < films.size(); ++k) {
        if (passes[k] == 0) continue;
        const double w = static_cast<double>(passes[k]);
        const std::vector<float>& f = *films[k];
        for (std::size_t j = 0; j < sum.size(); ++j) sum[j] += w * static_cast<double>(f[j]);
    }
    std::vector<float> out(sum.size());
    for (std::size_t j = 0; j < sum.size(); ++j) out[j] = static_cast<float>(sum[j] / total);
    return out;
}

std::vector<std::pair<std::uint64_t, std::uint64_t>> pass_ranges(std::vector<std::uint64_t> indices) {
    std::sort(indices.begin(), indices.end());
    std::vector<std::pair<std::uint64_t, std::uint64_t>> ranges;
    for (std::uint64_t i : indices) {
        if (!ranges.empty() && ranges.back().second == i)
            ++ranges.back().second;
        else if (ranges.empty() || ranges.back().second < i)
            ranges.push_back({i, i + 1});
    }
    return ranges;
}

}  // namespace glslppm
