// The GPU generators of shaders/common/rng.glsl against CPU reimplementations, and simple
// statistics of their streams. dieharder (scripts/dieharder.sh) does the thorough part.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

#include "gl/shader_program.h"
#include "gl_probe.h"
#include "render/gpu_layout.h"
#include "render/rng_seed.h"

namespace glslppm {
namespace {

using gl::ComputeProgram;
using gl_probe::gl_thread;

// The constants of the paper's Figure 4.
constexpr double kQ[4] = {1225, 1585, 2457, 2098};
constexpr double kR[4] = {1112, 367, 92, 265};
constexpr double kA[4] = {3423, 2646, 1707, 1999};
constexpr double kM[4] = {4194287, 4194277, 4194191, 4194167};
constexpr float kBelowOne = 0x1.fffffep-1f;  // rng_next's clamp of GPURnd's rare 1.0

// Figure 4 in double precision, step by step as printed; GLSL's mod(x, y) is
// x - y * floor(x / y) and sign(0) is 0.
struct PaperCpu {
    double s[4];
    double next() {
        for (int i = 0; i < 4; ++i) {
            double beta = std::floor(s[i] / kQ[i]);
            const double mod = s[i] - kQ[i] * std::floor(s[i] / kQ[i]);
            const double p = kA[i] * mod - beta * kR[i];
            const double sign_minus_p = -p > 0 ? 1.0 : (-p < 0 ? -1.0 : 0.0);
            beta = (sign_minus_p + 1.0) * 0.5 * kM[i];
            s[i] = p + beta;
        }
        const double d = s[0] / kM[0] - s[1] / kM[1] + s[2] / kM[2] - s[3] / kM[3];
        return d - std::floor(d);
    }
};

// PCG-RXS-M-XS-32 exactly as rng.glsl's RNG_PCG.
std::uint32_t pcg_permute(std::uint32_t s) {
    const std::uint32_t word = ((s >> ((s >> 28u) + 4u)) ^ s) * 277803737u;
    return (word >> 22u) ^ word;
}
std::uint32_t pcg_hash(std::uint32_t v) { return pcg_permute(v * 747796405u + 2891336453u); }
std::uint32_t pcg_load(std::uint32_t thread, std::uint32_t seed) {
    return pcg_hash(pcg_hash(thread) + pcg_hash(seed ^ 0x9E3779B9u));
}
float pcg_next(std::uint32_t& s) {
    const std::uint32_t old = s;
    s = old * 747796405u + 2891336453u;
    return static_cast<float>(pcg_permute(old) >> 8u) * (1.0f / 16777216.0f);
}

struct Stream {
    std::vector<float> values;              // values[k * threads + t]
    std::vector<float> paper_states;        // 4 per entry, RNG_PAPER
    std::vector<std::uint32_t> pcg_states;  // RNG_PCG
};

// Runs rng_stream.comp with RNG_STREAM_STATES and reads everything back.
Stream run_stream(bool paper, std::uint32_t threads, std::uint32_t per_thread,
                  const std::vector<glm::vec4>& seeds, std::uint32_t pcg_seed) {
    return gl_thread().call([&] {
        ComputeProgram program("tests/rng_stream.comp",
                               {{paper ? "RNG_PAPER" : "RNG_PCG", ""}, {"RNG_STREAM_STATES", ""}});
        const std::size_t n = std::size_t{threads} * per_thread;
        const std::size_t state_bytes = paper ? 16 : 4;
        const gl_probe::Buffers buffers{
            {0, nullptr, n * 4},
            {1, nullptr, n * state_bytes},
            {BINDING_RNG_STATES, seeds.empty() ? nullptr : seeds.data(), seeds.size() * 16}};
        program.use();
        glUniform1ui(program.uniform("u_threads"), threads);
        glUniform1ui(program.uniform("u_per_thread"), per_thread);
        glUniform1ui(program.uniform("u_rng_seed"), pcg_seed);
        gl_probe::dispatch_items(threads);
        Stream s;
        s.values = buffers.read<float>(0, n);
        if (paper)
            s.paper_states = buffers.read<float>(1, n * 4);
        else
            s.pcg_states = buffers.read<std::uint32_t>(1, n);
        return s;
    });
}

// Mean within 5 sigma, 256-bin chi-square within 5 sigma of its mean (255 +- 5 sqrt(510)),
// and lag-1 correlation within 5 / sqrt(n) along `values` and along each thread's sequence.
void expect_uniform(const std::vector<float>& values, std::uint32_t threads, const char* what) {
    const double n = static_cast<double>(values.size());
    double sum = 0.0;
    std::vector<double> bins(256, 0.0);
    for (float x : values) {
        ASSERT_GE(x, 0.0f);
        ASSERT_LT(x, 1.0f);
        sum += x;
        bins[static_cast<int>(x * 256.0f)] += 1.0;
    }
    const double mean = sum / n;
    EXPECT_NEAR(mean, 0.5, 5.0 * std::sqrt(1.0 / 12.0 / n)) << what;
    double chi2 = 0.0;
    for (double b : bins) chi2 += (b - n / 256) * (b - n / 256) / (n / 256);
    EXPECT_LT(chi2, 255.0 + 5.0 * std::sqrt(510.0)) << what;
    EXPECT_GT(chi2, 255.0 - 5.0 * std::sqrt(510.0)) << what;
    auto lag_correlation = [&](std::size_t lag) {
        double c = 0.0, v = 0.0;
        for (std::size_t i = 0; i + lag < values.size(); ++i) {
            c += (values[i] - mean) * (values[i + lag] - mean);
        }
        for (float x : values) v += (x - mean) * (x - mean);
        return c / v;
    };
    const double neighbours = lag_correlation(1);      // thread t and t+1, same draw
    const double sequence = lag_correlation(threads);  // draws k and k+1 of one thread
    EXPECT_LT(std::abs(neighbours), 5.0 / std::sqrt(n)) << what;
    EXPECT_LT(std::abs(sequence), 5.0 / std::sqrt(n)) << what;
    std::printf("%s: n %.0f, mean %.6f, chi2(255) %.1f, lag-1 corr %.2e (threads) %.2e (draws)\n",
                what, n, mean, chi2, neighbours, sequence);
}

TEST(RngSeed, PaperSeedsAreIntegersInRangeAndDeterministic) {
    const std::vector<glm::vec4> seeds = paper_rng_seeds(100000, 42);
    for (const glm::vec4& s : seeds) {
        for (int i = 0; i < 4; ++i) {
            ASSERT_EQ(s[i], std::floor(s[i]));
            ASSERT_GE(s[i], 1.0f);
            ASSERT_LE(s[i], static_cast<float>(kPaperRngModuli[i] - 1));
        }
    }
    EXPECT_EQ(seeds[12345], paper_rng_seeds(100000, 42)[12345]);
    EXPECT_NE(seeds[0], paper_rng_seeds(1, 43)[0]);
    // Component 0 over 100000 threads: mean near m/2.
    double mean = 0.0;
    for (const glm::vec4& s : seeds) mean += s[0];
    mean /= static_cast<double>(seeds.size());
    EXPECT_NEAR(mean / kM[0], 0.5, 5.0 * std::sqrt(1.0 / 12.0 / 100000.0));
}

TEST(RngSeed, XorshiftMatchesMarsaglia) {
    // Marsaglia's xorshift64 (13, 7, 17) from a known state: checked by hand-stepping.
    Xorshift64 rng(0);
    std::uint64_t x = 0x9E3779B97F4A7C15ull;  // splitmix64(0), computed below
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    x ^= x >> 31;
    for (int i = 0; i < 5; ++i) {
        x ^= x << 13, x ^= x >> 7, x ^= x << 17;
        EXPECT_EQ(rng.next(), x);
    }
}

// The claim behind running Figure 4 in float: for integer states below 2^22 every step is
// exact. Checked for every state of all four generators, with IEEE division and with the
// division done as multiplication by a rounded reciprocal (what GPU compilers may emit).
TEST(RngPaper, EveryFloatStepIsExactForAllStates) {
    for (int i = 0; i < 4; ++i) {
        const auto q = static_cast<float>(kQ[i]), r = static_cast<float>(kR[i]);
        const auto a = static_cast<float>(kA[i]), m = static_cast<float>(kM[i]);
        const float reciprocal_q = 1.0f / q;
        const auto qi = static_cast<std::uint64_t>(kQ[i]), ai = static_cast<std::uint64_t>(kA[i]);
        const auto mi = static_cast<std::uint64_t>(kM[i]);
        long reciprocal_floor_off = 0;
        for (std::uint64_t s = 1; s < mi; ++s) {
            const auto fs = static_cast<float>(s);
            const std::uint64_t expected = ai * s % mi;  // the LCG step, in integers
            // IEEE float, as Figure 4 prints it.
            const float beta = std::floor(fs / q);
            const float mod = fs - q * std::floor(fs / q);
            ASSERT_EQ(beta, static_cast<float>(s / qi)) << "s " << s;
            ASSERT_EQ(mod, static_cast<float>(s % qi)) << "s " << s;
            const float p = a * mod - beta * r;
            const float next = p + (std::copysign(1.0f, -p) * (p != 0.0f) + 1.0f) * 0.5f * m;
            ASSERT_EQ(next, static_cast<float>(expected)) << "generator " << i << " s " << s;
            // Division by reciprocal: floor may land one low at exact multiples of q, but
            // mod uses the same floor, so p comes out m higher and the correction still
            // lands on the right state (Schrage: m = a q + r).
            const float beta_r = std::floor(fs * reciprocal_q);
            const float mod_r = fs - q * beta_r;
            reciprocal_floor_off += beta_r != beta;
            const float p_r = a * mod_r - beta_r * r;
            const float next_r =
                p_r + (std::copysign(1.0f, -p_r) * (p_r != 0.0f) + 1.0f) * 0.5f * m;
            ASSERT_EQ(next_r, static_cast<float>(expected)) << "generator " << i << " s " << s;
            // Force that case: a floor one low at every exact multiple of q.
            if (s % qi == 0) {
                const float beta_low = beta - 1.0f;
                const float p_low = a * (fs - q * beta_low) - beta_low * r;
                const float next_low =
                    p_low + (std::copysign(1.0f, -p_low) * (p_low != 0.0f) + 1.0f) * 0.5f * m;
                ASSERT_EQ(next_low, static_cast<float>(expected)) << "generator " << i;
            }
        }
        std::printf(
            "generator %d: reciprocal division floors one low for %ld of %llu states, "
            "state still exact\n",
            i, reciprocal_floor_off, static_cast<unsigned long long>(mi - 1));
    }
}

TEST(RngPaper, GpuStatesMatchCpuBitExactlyAndOutputsWithinRounding) {
    constexpr std::uint32_t kThreads = 256, kDraws = 4096;
    const std::vector<glm::vec4> seeds = paper_rng_seeds(kThreads, 2015);
    const Stream gpu = run_stream(true, kThreads, kDraws, seeds, 0);
    double max_error = 0.0;
    std::size_t bit_equal_to_float = 0, clamped = 0;
    for (std::uint32_t t = 0; t < kThreads; ++t) {
        PaperCpu cpu{{seeds[t][0], seeds[t][1], seeds[t][2], seeds[t][3]}};
        for (std::uint32_t k = 0; k < kDraws; ++k) {
            const double expected = cpu.next();
            const std::size_t at = std::size_t{k} * kThreads + t;
            for (int i = 0; i < 4; ++i) {
                ASSERT_EQ(gpu.paper_states[at * 4 + i], static_cast<float>(cpu.s[i]))
                    << "thread " << t << " draw " << k << " component " << i;
            }
            // The output rounds (float division, a float sum up to 2 in magnitude): compare
            // on the circle, since a sum just below an integer may round either way.
            const float got = gpu.values[at];
            double error = std::abs(got - expected);
            error = std::min(error, 1.0 - error);
            max_error = std::max(max_error, error);
            // Figure 4's output in float, IEEE division, dot summed left to right.
            float d = static_cast<float>(cpu.s[0]) / static_cast<float>(kM[0]);
            d = d - static_cast<float>(cpu.s[1]) / static_cast<float>(kM[1]);
            d = d + static_cast<float>(cpu.s[2]) / static_cast<float>(kM[2]);
            d = d - static_cast<float>(cpu.s[3]) / static_cast<float>(kM[3]);
            const float f = std::min(d - std::floor(d), kBelowOne);
            bit_equal_to_float += std::memcmp(&f, &got, 4) == 0;
            clamped += got == kBelowOne;
        }
    }
    // GLSL allows 2.5 ulp for division; four quotients below 1 plus three sums below 2
    // round to at most about 13 * 2^-24.
    EXPECT_LE(max_error, 16.0 / 16777216.0);
    std::printf(
        "paper: %u threads x %u draws: states bit-exact; output max error %.2f * 2^-24, "
        "%.4f%% bit-equal to a CPU float evaluation, %zu clamped\n",
        kThreads, kDraws, max_error * 16777216.0,
        100.0 * bit_equal_to_float / (double(kThreads) * kDraws), clamped);
    expect_uniform(gpu.values, kThreads, "paper");
}

TEST(RngPcg, GpuStreamMatchesCpuBitExactly) {
    constexpr std::uint32_t kThreads = 256, kDraws = 4096, kSeed = 77;
    const Stream gpu = run_stream(false, kThreads, kDraws, {}, kSeed);
    for (std::uint32_t t = 0; t < kThreads; ++t) {
        std::uint32_t state = pcg_load(t, kSeed);
        for (std::uint32_t k = 0; k < kDraws; ++k) {
            const float expected = pcg_next(state);
            const std::size_t at = std::size_t{k} * kThreads + t;
            ASSERT_EQ(gpu.pcg_states[at], state) << "thread " << t << " draw " << k;
            ASSERT_EQ(std::memcmp(&gpu.values[at], &expected, 4), 0)
                << "thread " << t << " draw " << k << ": " << gpu.values[at] << " vs " << expected;
        }
    }
    expect_uniform(gpu.values, kThreads, "pcg");
}

TEST(RngPcg, DifferentSeedsGiveUnrelatedStreams) {
    // Passes use consecutive seeds: the same thread in consecutive passes must not repeat or
    // shift another thread's stream.
    constexpr std::uint32_t kThreads = 4096, kDraws = 64;
    const Stream a = run_stream(false, kThreads, kDraws, {}, 1000);
    const Stream b = run_stream(false, kThreads, kDraws, {}, 1001);
    std::vector<float> both = a.values;
    both.insert(both.end(), b.values.begin(), b.values.end());
    expect_uniform(both, kThreads, "pcg seeds 1000+1001");
    double c = 0.0;
    for (std::size_t i = 0; i < a.values.size(); ++i)
        c += (a.values[i] - 0.5) * (b.values[i] - 0.5);
    c /= static_cast<double>(a.values.size()) / 12.0;
    EXPECT_LT(std::abs(c), 5.0 / std::sqrt(static_cast<double>(a.values.size())));
}

}  // namespace
}  // namespace glslppm
