// The lobes of shaders/common/lobes.glsl, run on the real driver through the test program
// shaders/tests/bsdf_probe.comp:
// - sampling matches the density: a chi-squared goodness-of-fit test per lobe over a
//   (theta, phi) histogram of the sampler's directions against the integral of bsdf_pdf
//   over each bin (Mitsuba's BSDF test is the model), for roughness 0.05 to 1 and incident
//   angles from normal to grazing;
// - energy: the mean sample weight is the lobe's albedo: 1 for the compensated white
//   conductor and the white plastic, the CPU integral of render/microfacet_tables.cpp for
//   single-scatter GGX, reflection + transmission = 1 for a clear rough dielectric;
// - reciprocity of the reflection lobes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "chi_squared.h"
#include "gl_probe.h"
#include "gl/shader_program.h"
#include "render/gpu_layout.h"
#include "render/microfacet_tables.h"
#include "render/scene_preparation.h"

namespace glslppm {
namespace {

using gl::ComputeProgram;
using gl_probe::gl_thread;

constexpr double kPi = 3.14159265358979323846;

struct Sample {
    glm::vec4 wi_ok;
    glm::vec4 weight_pdf;
};

struct Evaluation {
    glm::vec4 f_pdf;
    glm::vec4 f_swapped;
};

// One material under test, with its table as the renderer builds it.
class Probe {
  public:
    explicit Probe(const Material& m) {
        records_ = material_records({m}, {0u}, false);
    }

    // Directions in world space; `normal` is the surface's (+z unless given).
    std::vector<Sample> sample(glm::vec3 wo, std::uint32_t count, std::uint32_t seed,
                               bool adjoint, glm::vec3 normal = {0.0f, 0.0f, 1.0f}) const {
        std::vector<Sample> out(count);
        run(0, wo, {}, count, seed, adjoint, out.data(), out.size() * sizeof(Sample), normal);
        return out;
    }

    // In dispatches of at most 1M directions (32 MiB of results: llvmpipe's storage
    // blocks hold 128 MiB).
    std::vector<Evaluation> evaluate(glm::vec3 wo, const std::vector<glm::vec4>& dirs) const {
        std::vector<Evaluation> out(dirs.size());
        constexpr std::size_t kChunk = 1u << 20;
        for (std::size_t first = 0; first < dirs.size(); first += kChunk) {
            const std::size_t n = std::min(kChunk, dirs.size() - first);
            const std::vector<glm::vec4> part(dirs.begin() + first, dirs.begin() + first + n);
            run(1, wo, part, static_cast<std::uint32_t>(n), 0, false, out.data() + first,
                n * sizeof(Evaluation));
        }
        return out;
    }

  private:
    void run(std::uint32_t mode, glm::vec3 wo, const std::vector<glm::vec4>& in,
             std::uint32_t count, std::uint32_t seed, bool adjoint, void* out,
             std::size_t out_bytes, glm::vec3 normal = {0.0f, 0.0f, 1.0f}) const {
        gl_thread().call([&] {
            static ComputeProgram program("tests/bsdf_probe.comp", {{"HAS_ROUGH_LOBES", "1"}});
            FrameBlock frame{};
            frame.glossy_threshold = 0.0f;
            GLuint ubo = 0, buffers[3];
            glGenBuffers(1, &ubo);
            glBindBuffer(GL_UNIFORM_BUFFER, ubo);
            glBufferData(GL_UNIFORM_BUFFER, sizeof frame, &frame, GL_STATIC_DRAW);
            glBindBufferBase(GL_UNIFORM_BUFFER, BINDING_FRAME, ubo);
            glGenBuffers(3, buffers);
            const glm::vec4 none(0.0f);
            const void* data[3] = {records_.data(), in.empty() ? &none : in.data(), nullptr};
            const std::size_t bytes[3] = {records_.size() * 16, std::max<std::size_t>(in.size(), 1) * 16,
                                          out_bytes};
            const GLuint bindings[3] = {BINDING_MATERIALS, 20, 21};
            for (int b = 0; b < 3; ++b) {
                glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers[b]);
                glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(bytes[b]), data[b],
                             GL_DYNAMIC_COPY);
                glBindBufferBase(GL_SHADER_STORAGE_BUFFER, bindings[b], buffers[b]);
            }
            program.use();
            glUniform1ui(program.uniform("u_mode"), mode);
            glUniform1ui(program.uniform("u_count"), count);
            glUniform1i(program.uniform("u_material"), 0);
            glUniform3f(program.uniform("u_wo"), wo.x, wo.y, wo.z);
            glUniform3f(program.uniform("u_n"), normal.x, normal.y, normal.z);
            glUniform1ui(program.uniform("u_seed"), seed);
            glUniform1ui(program.uniform("u_adjoint"), adjoint ? 1u : 0u);
            const std::uint32_t groups = (count + 63) / 64;
            glDispatchCompute(std::min(groups, 65535u), (groups + 65534) / 65535, 1);
            glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
            glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers[2]);
            glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(out_bytes), out);
            glDeleteBuffers(3, buffers);
            glDeleteBuffers(1, &ubo);
            EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
        });
    }

    std::vector<glm::vec4> records_;
};

glm::vec3 incident(double theta_degrees) {
    const double t = theta_degrees * kPi / 180.0;
    return {static_cast<float>(std::sin(t)), 0.0f, static_cast<float>(std::cos(t))};
}

using chi_squared::gamma_q;

constexpr int kThetaBins = 18, kPhiBins = 36;

glm::vec4 direction(double theta, double phi) {
    return {static_cast<float>(std::sin(theta) * std::cos(phi)),
            static_cast<float>(std::sin(theta) * std::sin(phi)), static_cast<float>(std::cos(theta)),
            0.0f};
}

// The integrals of bsdf_pdf over the given (theta, phi) bins, by adaptive subdivision: each
// cell is integrated with 4 x 4 and 8 x 8 midpoints, and cells where the two differ by more
// than `tolerance` split into four, to 14 levels. Every bin starts split `min_depth` times,
// so that a peak narrower than the first grid cannot look like zero twice.
std::vector<double> bin_integrals(const Probe& probe, glm::vec3 wo, const std::vector<int>& bins,
                                  int min_depth, double tolerance) {
    struct Cell {
        double t0, t1, p0, p1;
        std::size_t bin;
    };
    const double dt = kPi / kThetaBins, dp = 2.0 * kPi / kPhiBins;
    std::vector<Cell> cells;
    for (std::size_t k = 0; k < bins.size(); ++k) {
        const int bt = bins[k] / kPhiBins, bp = bins[k] % kPhiBins;
        const int split = 1 << min_depth;
        for (int i = 0; i < split; ++i)
            for (int j = 0; j < split; ++j)
                cells.push_back({(bt + double(i) / split) * dt, (bt + double(i + 1) / split) * dt,
                                 (bp + double(j) / split) * dp, (bp + double(j + 1) / split) * dp, k});
    }
    std::vector<double> sums(bins.size(), 0.0);
    for (int level = min_depth; level < 14 && !cells.empty(); ++level) {
        std::vector<glm::vec4> dirs;
        std::vector<double> area;
        for (const Cell& c : cells)
            for (int n : {4, 8})
                for (int i = 0; i < n; ++i)
                    for (int j = 0; j < n; ++j) {
                        const double theta = c.t0 + (i + 0.5) / n * (c.t1 - c.t0);
                        const double phi = c.p0 + (j + 0.5) / n * (c.p1 - c.p0);
                        dirs.push_back(direction(theta, phi));
                        area.push_back(std::sin(theta) * (c.t1 - c.t0) / n * (c.p1 - c.p0) / n);
                    }
        const std::vector<Evaluation> e = probe.evaluate(wo, dirs);
        std::vector<Cell> next;
        std::size_t at = 0;
        for (const Cell& c : cells) {
            double coarse = 0.0, fine = 0.0;
            for (int k = 0; k < 16; ++k, ++at) coarse += e[at].f_pdf.w * area[at];
            for (int k = 0; k < 64; ++k, ++at) fine += e[at].f_pdf.w * area[at];
            if (std::abs(fine - coarse) <= tolerance || level == 13) {
                sums[c.bin] += fine;
                continue;
            }
            const double tm = 0.5 * (c.t0 + c.t1), pm = 0.5 * (c.p0 + c.p1);
            next.push_back({c.t0, tm, c.p0, pm, c.bin});
            next.push_back({c.t0, tm, pm, c.p1, c.bin});
            next.push_back({tm, c.t1, c.p0, pm, c.bin});
            next.push_back({tm, c.t1, pm, c.p1, c.bin});
        }
        cells = std::move(next);
    }
    return sums;
}

struct FitResult {
    double p_value;
    double chi2;
    int dof;
    double albedo;  // mean weight (green channel), failures counted as 0
};

// Pearson's chi-squared test of the sampler against the density, the expected counts from
// adaptive integration (bin_integrals); bins expecting fewer than 5 samples are pooled.
FitResult chi_squared(const Probe& probe, glm::vec3 wo, std::uint32_t count, std::uint32_t seed) {
    const std::vector<Sample> samples = probe.sample(wo, count, seed, false);
    std::vector<double> observed(kThetaBins * kPhiBins, 0.0);
    double weight_sum = 0.0;

    for (const Sample& s : samples) {
        if (s.wi_ok.w < 0.5) continue;
        weight_sum += s.weight_pdf.y;
        const glm::vec3 wi = glm::normalize(glm::vec3(s.wi_ok));
        const double theta = std::acos(std::clamp(double(wi.z), -1.0, 1.0));
        double phi = std::atan2(double(wi.y), double(wi.x));
        if (phi < 0.0) phi += 2.0 * kPi;
        const int bt = std::min(kThetaBins - 1, int(theta / (kPi / kThetaBins)));
        const int bp = std::min(kPhiBins - 1, int(phi / (2.0 * kPi / kPhiBins)));
        observed[bt * kPhiBins + bp] += 1.0;
    }
    std::vector<int> open(observed.size());
    for (std::size_t k = 0; k < open.size(); ++k) open[k] = static_cast<int>(k);
    std::vector<double> integral(observed.size(), 0.0);
    // Bins whose count disagrees with their integral are integrated again from a finer
    // start: the final integral is the better one either way, and what is tested.
    for (int min_depth : {0, 4, 7}) {
        const std::vector<double> sums = bin_integrals(probe, wo, open, min_depth, 0.02 / count);
        std::vector<int> still;
        for (std::size_t k = 0; k < open.size(); ++k) {
            integral[open[k]] = sums[k];
            const double e = sums[k] * count, o = observed[open[k]];
            if (std::abs(o - e) > 3.0 * std::sqrt(e) + 3.0) still.push_back(open[k]);
        }
        open = still;
        if (open.empty()) break;
    }
    std::vector<double> expected(observed.size());
    for (std::size_t k = 0; k < expected.size(); ++k) expected[k] = integral[k] * count;
    double chi2 = 0.0, pooled_observed = 0.0, pooled_expected = 0.0;
    int bins = 0;
    for (std::size_t k = 0; k < observed.size(); ++k) {
        if (expected[k] < 5.0) {
            pooled_observed += observed[k];
            pooled_expected += expected[k];
            continue;
        }
        chi2 += (observed[k] - expected[k]) * (observed[k] - expected[k]) / expected[k];
        if (std::getenv("GLSLPPM_CHI2_BINS") &&
            std::abs(observed[k] - expected[k]) > 5.0 * std::sqrt(expected[k]))
            std::printf("    bin theta %d phi %d: observed %.0f expected %.1f\n",
                        int(k) / kPhiBins, int(k) % kPhiBins, observed[k], expected[k]);
        ++bins;
    }
    if (pooled_expected >= 5.0) {
        chi2 += (pooled_observed - pooled_expected) * (pooled_observed - pooled_expected) /
                pooled_expected;
        ++bins;
    } else {
        // Too little density there to test by counts: no sample may land where none is due.
        EXPECT_LE(pooled_observed, 5.0 + 5.0 * pooled_expected)
            << "samples where the density is (almost) zero";
    }
    const int dof = bins - 1;
    return {gamma_q(0.5 * dof, 0.5 * chi2), chi2, dof, weight_sum / count};
}

Material lobe(MaterialKind kind, float roughness) {
    Material m;
    m.kind = kind;
    m.color = glm::vec3(1.0f);
    m.roughness = roughness;
    m.ior = 1.5f;
    return m;
}

const float kRoughness[] = {0.05f, 0.2f, 0.5f, 1.0f};
const double kAngles[] = {0.0, 40.0, 70.0, 87.0};
// 64 tests at a significance of 1% overall (Sidak): 1 - 0.99^(1/64) per test.
constexpr double kSignificance = 1.57e-4;

void fit_all(const char* name, MaterialKind kind, bool inside = false) {
    std::uint32_t seed = 1;
    for (float r : kRoughness)
        for (double angle : kAngles) {
            const Probe probe(lobe(kind, r));
            glm::vec3 wo = incident(angle);
            if (inside) wo.z = -wo.z;
            const FitResult fit = chi_squared(probe, wo, 200000, seed++);
            std::printf("  %s roughness %.2f, %2.0f deg%s: chi2 %.1f / %d dof, p = %.4f\n", name,
                        r, angle, inside ? " (inside)" : "", fit.chi2, fit.dof, fit.p_value);
            EXPECT_GT(fit.p_value, kSignificance)
                << name << " roughness " << r << " at " << angle << " degrees";
        }
}

TEST(BsdfProbe, ConductorSamplingMatchesItsDensity) { fit_all("conductor", MaterialKind::Conductor); }
TEST(BsdfProbe, PlasticSamplingMatchesItsDensity) { fit_all("plastic", MaterialKind::Plastic); }
TEST(BsdfProbe, DielectricSamplingMatchesItsDensity) {
    fit_all("dielectric", MaterialKind::Dielectric);
    fit_all("dielectric", MaterialKind::Dielectric, true);
}
TEST(BsdfProbe, TranslucentAndDiffuseSamplingMatchTheirDensity) {
    for (MaterialKind kind : {MaterialKind::Translucent, MaterialKind::Diffuse}) {
        const Probe probe(lobe(kind, 0.0f));
        for (double angle : kAngles) {
            const FitResult fit = chi_squared(probe, incident(angle), 200000, 7);
            std::printf("  kind %d, %2.0f deg: p = %.4f\n", int(kind), angle, fit.p_value);
            EXPECT_GT(fit.p_value, kSignificance);
            EXPECT_NEAR(fit.albedo, 1.0, 1e-5);  // white: the weight is the colour
        }
    }
}

// The mean weight of the sampler at wo: the lobe's directional albedo (flux: adjoint).
double albedo(const Probe& probe, glm::vec3 wo, bool adjoint, std::uint32_t count = 400000) {
    const std::vector<Sample> samples = probe.sample(wo, count, 99, adjoint);
    double sum = 0.0;
    for (const Sample& s : samples)
        if (s.wi_ok.w > 0.5) sum += s.weight_pdf.y;
    return sum / count;
}

TEST(BsdfProbe, CompensatedWhiteConductorReflectsAtLeast099) {
    for (float r : {0.05f, 0.2f, 0.35f, 0.5f, 0.75f, 1.0f})
        for (double angle : {0.0, 20.0, 40.0, 60.0, 75.0, 85.0, 89.0}) {
            const double e = albedo(Probe(lobe(MaterialKind::Conductor, r)), incident(angle), false);
            std::printf("  white conductor roughness %.2f, %2.0f deg: albedo %.4f\n", r, angle, e);
            EXPECT_GE(e, 0.99) << "roughness " << r << " at " << angle;
            EXPECT_LE(e, 1.01) << "roughness " << r << " at " << angle;
        }
}

TEST(BsdfProbe, SingleScatterGgxLosesWhatItsAlbedoSays) {
    // The GLSL sampler's mean weight against the CPU's deterministic integral of the same
    // albedo (the table the compensation reads): they agree within the sampling noise.
    for (float r : {0.2f, 0.5f, 1.0f})
        for (double angle : {0.0, 60.0, 85.0}) {
            Material m = lobe(MaterialKind::Conductor, r);
            m.multiscatter = false;
            const double e = albedo(Probe(m), incident(angle), false);
            const double cpu = ggx_albedo(AlbedoLobe::WhiteConductor, 1.5f,
                                          static_cast<float>(std::cos(angle * kPi / 180.0)), r, 256);
            std::printf("  single-scatter roughness %.2f, %2.0f deg: GLSL %.4f, CPU %.4f\n", r,
                        angle, e, cpu);
            EXPECT_NEAR(e, cpu, 0.003);
        }
}

// At grazing incidence a sample's weight f cos / pdf stays bounded. On a mesh the shading
// frame is rotated, so a grazing wo and its mirror direction, nearly opposite in the tangent
// plane, cancel there to rounding (about 1e-7) against a normal component of 2 cos: the half
// vector normalised from wo + wi is tilted by as much as a narrow lobe's width. The density
// took wo.h from it, which came out 0, while f did not: weights up to 1e14 (session 22, the
// showcase's gold ring, roughness 0.02, at its silhouette; common/microfacet.glsl,
// ggx_reflection_pdf). Measured largest weights with the fix (tilted normal, 2^20 samples
// each): conductor 0.02 about 230, which is its multiple-scattering lobe, cosine-sampled,
// at (1 - E(wi)) / (1 - E_avg) = 0.07 / 1.6e-4; plastic and dielectric below 2. Before it,
// the conductor's reached 3.6e12 to 4.9e14 (roughness 0.02 and 0.05 at cos 1e-4 and 1e-5;
// the plastic layer shares the density and the fix, the dielectric checks its half vector).
// The bound, 1,000, is far above the first and far below the second. It holds the worst
// sample, not the mean: a 1% bias in the lobes' albedo is the albedo tests' to catch (above).
TEST(BsdfProbe, GrazingSampleWeightsStayBounded) {
    const glm::vec3 n = glm::normalize(glm::vec3(0.3f, -0.5f, 0.81f));
    const glm::vec3 t = glm::normalize(glm::cross(n, glm::vec3(0.2f, 0.9f, 0.1f)));
    for (MaterialKind kind : {MaterialKind::Conductor, MaterialKind::Plastic,
                              MaterialKind::Dielectric})
        for (float r : {0.02f, 0.05f, 0.2f})
            for (double cos_o : {1e-2, 1e-3, 1e-4, 1e-5}) {
                Material m = lobe(kind, r);
                m.color = {1.0f, 0.78f, 0.34f};  // the showcase's gold
                m.schlick = kind == MaterialKind::Conductor;
                const Probe probe(m);
                const glm::vec3 wo = glm::normalize(
                    static_cast<float>(cos_o) * n +
                    static_cast<float>(std::sqrt(1.0 - cos_o * cos_o)) * t);
                double largest = 0.0;
                for (const Sample& x : probe.sample(wo, 1u << 20, 5, false, n))
                    if (x.wi_ok.w > 0.5)
                        largest = std::max({largest, double(x.weight_pdf.x),
                                            double(x.weight_pdf.y), double(x.weight_pdf.z)});
                std::printf("  kind %d roughness %.2f, cos %.0e: largest weight %.4g\n",
                            int(kind), r, cos_o, largest);
                EXPECT_LE(largest, 1000.0) << "kind " << int(kind) << " roughness " << r
                                           << " at cos " << cos_o;
            }
}

// Refraction follows Cycles' convention (docs/materials.md): the eye paths' kernel carries no
// eta^2 across a refraction, so its sampler's mean weight is R + T = 1 from either side
// (photons carry that kernel's adjoint, which scales by eta^2).
TEST(BsdfProbe, ClearRoughDielectricConservesReflectionPlusTransmission) {
    for (float r : {0.05f, 0.2f, 0.5f, 1.0f})
        for (double angle : {0.0, 45.0, 80.0, 88.0})
            for (bool inside : {false, true}) {
                glm::vec3 wo = incident(angle);
                if (inside) wo.z = -wo.z;
                const double e = albedo(Probe(lobe(MaterialKind::Dielectric, r)), wo, false);
                std::printf("  dielectric roughness %.2f, %2.0f deg%s: R + T %.4f\n", r, angle,
                            inside ? " (inside)" : "", e);
                EXPECT_NEAR(e, 1.0, 0.01) << "roughness " << r << " at " << angle;
            }
}

TEST(BsdfProbe, WhitePlasticReflectsEverything) {
    for (float r : {0.0f, 0.05f, 0.2f, 0.5f, 1.0f})
        for (double angle : {0.0, 45.0, 80.0, 88.0}) {
            const double e = albedo(Probe(lobe(MaterialKind::Plastic, r)), incident(angle), false);
            std::printf("  white plastic roughness %.2f, %2.0f deg: albedo %.4f\n", r, angle, e);
            EXPECT_NEAR(e, 1.0, 0.01) << "roughness " << r << " at " << angle;
        }
}

TEST(BsdfProbe, ReflectionLobesAreReciprocal) {
    for (MaterialKind kind : {MaterialKind::Conductor, MaterialKind::Plastic, MaterialKind::Diffuse})
        for (float r : {0.1f, 0.5f, 1.0f}) {
            Material m = lobe(kind, r);
            m.color = {0.9f, 0.6f, 0.3f};
            m.schlick = true;
            const Probe probe(m);
            std::vector<glm::vec4> dirs;
            for (int i = 0; i < 16; ++i)
                for (int j = 0; j < 16; ++j)
                    dirs.push_back(direction((i + 0.5) / 16 * 0.5 * kPi * 0.98, (j + 0.5) / 16 * 2.0 * kPi));
            for (double angle : {10.0, 50.0, 80.0}) {
                const std::vector<Evaluation> e = probe.evaluate(incident(angle), dirs);
                double total = 0.0;
                for (const Evaluation& v : e) total += v.f_pdf.x;
                EXPECT_GT(total, 0.0) << "kind " << int(kind) << ": f is zero everywhere";
                for (std::size_t k = 0; k < e.size(); ++k)
                    for (int c = 0; c < 3; ++c) {
                        const double a = e[k].f_pdf[c], b = e[k].f_swapped[c];
                        ASSERT_NEAR(a, b, 2e-4 * std::max(std::abs(a), 1.0))
                            << "kind " << int(kind) << " roughness " << r;
                    }
            }
        }
}

}  // namespace
}  // namespace glslppm
