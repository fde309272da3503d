// CPU seeding of the paper's float-only generator (shaders/common/rng.glsl, RNG_PAPER).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <glm/vec4.hpp>
#include <vector>

namespace glslppm {

// The moduli of GPURnd's four multiplicative LCGs (Hachisuka 2015, Figure 4).
inline constexpr std::array<std::uint32_t, 4> kPaperRngModuli = {4194287u, 4194277u, 4194191u,
                                                                 4194167u};

// Marsaglia's xorshift64 (J. Stat. Softw. 8(14), 2003; shifts 13, 7, 17), the per-thread
// seeder the paper names. The seed goes through splitmix64 first so that small or similar
// seeds (0, 1, 2, ...) start from unrelated, non-zero states.
class Xorshift64 {
  public:
    explicit Xorshift64(std::uint64_t seed);
    std::uint64_t next();

  private:
    std::uint64_t state_;
};

// `count` GPURnd states, one per thread: integer-valued floats, component i uniform in
// [1, m_i - 1] (a multiplicative LCG must never hold 0). Deterministic in `seed`.
std::vector<glm::vec4> paper_rng_seeds(std::size_t count, std::uint64_t seed);

}  // namespace glslppm
