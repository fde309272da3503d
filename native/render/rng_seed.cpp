#include "render/rng_seed.h"

namespace glslppm {

Xorshift64::Xorshift64(std::uint64_t seed) {
    // splitmix64 (Steele, Lea, Flood 2014): a bijection, so distinct seeds stay distinct.
    std::uint64_t z = seed + 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    state_ = z != 0 ? z : 0x9E3779B97F4A7C15ull;  // xorshift's one forbidden state is 0
}

std::uint64_t Xorshift64::next() {
    std::uint64_t x = state_;
    x ^= x << 13;
    x ^= x >> 7;
    x ^= x << 17;
    state_ = x;
    return x;
}

std::vector<glm::vec4> paper_rng_seeds(std::size_t count, std::uint64_t seed) {
    Xorshift64 rng(seed);
    std::vector<glm::vec4> seeds(count);
    for (glm::vec4& s : seeds) {
        for (int i = 0; i < 4; ++i) {
            // The modulo bias is below 2^-40 (2^64 / 4.2e6 draws per residue).
            const std::uint64_t span = kPaperRngModuli[i] - 1u;
            s[i] = static_cast<float>(1u + rng.next() % span);  // < 2^22: exact in float
        }
    }
    return seeds;
}

}  // namespace glslppm
