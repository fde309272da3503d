#include "render/microfacet_tables.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <utility>

#include <glm/glm.hpp>

namespace glslppm {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kMinAlpha = 1.0e-4;  // GGX_MIN_ALPHA

double lambda(double c, double a2) {
    const double c2 = c * c;
    const double t2 = std::max(0.0, 1.0 - c2) / std::max(c2, 1.0e-20);
    return 0.5 * (std::sqrt(1.0 + a2 * t2) - 1.0);
}

// Fresnel of a smooth dielectric, eta = n_incident / n_transmitted.
double fresnel(double cos_i, double eta, double& cos_t) {
    const double sin2_t = eta * eta * std::max(0.0, 1.0 - cos_i * cos_i);
    if (sin2_t >= 1.0) {
        cos_t = 0.0;
        return 1.0;
    }
    cos_t = std::sqrt(1.0 - sin2_t);
    const double rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    const double rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

// Heitz 2018's visible-normal sample for wo (wo.z > 0).
glm::dvec3 sample_visible(glm::dvec3 wo, double a, double u1, double u2) {
    const glm::dvec3 v = glm::normalize(glm::dvec3(a * wo.x, a * wo.y, wo.z));
    const double len2 = v.x * v.x + v.y * v.y;
    const glm::dvec3 t1 = len2 > 0.0 ? glm::dvec3(-v.y, v.x, 0.0) / std::sqrt(len2)
                                     : glm::dvec3(1.0, 0.0, 0.0);
    const glm::dvec3 t2 = glm::cross(v, t1);
    const double r = std::sqrt(u1), phi = 2.0 * kPi * u2;
    const double p1 = r * std::cos(phi);
    const double s = 0.5 * (1.0 + v.z);
    const double p2 = (1.0 - s) * std::sqrt(std::max(0.0, 1.0 - p1 * p1)) + s * r * std::sin(phi);
    const glm::dvec3 h = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0, 1.0 - p1 * p1 - p2 * p2)) * v;
    return glm::normalize(glm::dvec3(a * h.x, a * h.y, std::max(1.0e-7, h.z)));
}

}  // namespace

double ggx_albedo(AlbedoLobe lobe, float ior, float mu, float roughness, int strata) {
    const double a = std::max(double(roughness) * roughness, kMinAlpha), a2 = a * a;
    const double c = std::clamp(double(mu), 1.0e-3, 1.0);
    const glm::dvec3 wo(std::sqrt(1.0 - c * c), 0.0, c);
    const double go = 1.0 / (1.0 + lambda(c, a2));
    // n(wo side) / n(other side).
    const double eta = lobe == AlbedoLobe::DielectricInside ? ior : 1.0 / ior;
    double sum = 0.0;
    // The energy lost lies in the few visible normals near u1 = 1 (steep microfacets that send
    // the light below the horizon): the strata in u1 are packed there, u1 = 1 - (1 - s)^3,
    // each weighted by its width 3 (1 - s)^2 ds.
    for (int i = 0; i < strata; ++i)
        for (int j = 0; j < strata; ++j) {
            const double s = (i + 0.5) / strata;
            const double u1 = 1.0 - (1.0 - s) * (1.0 - s) * (1.0 - s);
            const double du = 3.0 * (1.0 - s) * (1.0 - s);
            const glm::dvec3 m = sample_visible(wo, a, u1, (j + 0.5) / strata);
            const double cm = glm::dot(wo, m);
            if (cm <= 0.0) continue;
            // E = E_m[sum over the branches of P(branch) G2 / G1]: both branches at once.
            double cos_t = 0.0;
            const double F = lobe == AlbedoLobe::WhiteConductor ? 1.0 : fresnel(cm, eta, cos_t);
            const glm::dvec3 r = 2.0 * cm * m - wo;
            if (r.z > 0.0) sum += du * F / (1.0 + lambda(c, a2) + lambda(r.z, a2)) / go;
            if (lobe == AlbedoLobe::DielectricOutside || lobe == AlbedoLobe::DielectricInside) {
                const glm::dvec3 t = -eta * wo + (eta * cm - cos_t) * m;
                if (F < 1.0 && t.z < 0.0)
                    sum += du * (1.0 - F) / (1.0 + lambda(c, a2) + lambda(-t.z, a2)) / go;
            }
        }
    return sum / (double(strata) * strata);
}

std::vector<float> albedo_table(AlbedoLobe lobe, float ior) {
    // Computed once per process for each lobe and index (about 0.1 s each).
    static std::mutex mutex;
    static std::map<std::pair<int, float>, std::vector<float>> tables;
    const std::lock_guard<std::mutex> lock(mutex);
    const std::pair<int, float> key{static_cast<int>(lobe), lobe == AlbedoLobe::WhiteConductor ? 1.0f : ior};
    if (auto it = tables.find(key); it != tables.end()) return it->second;
    constexpr int n = kAlbedoTableSize;
    constexpr int strata = 40;  // 1600 visible normals per entry: within 0.1% of 512^2
    std::vector<float> table(kAlbedoTableFloats);
    for (int j = 0; j < n; ++j) {
        const float roughness = float(j) / (n - 1);
        for (int i = 0; i < n; ++i) {
            const double x = double(i) / (n - 1);
            table[j * n + i] = static_cast<float>(
                ggx_albedo(lobe, ior, static_cast<float>(x * x), roughness, strata));
        }
        // 2 int E mu dmu = 4 int E(x) x^3 dx of the E linear in x = sqrt(mu) between the
        // nodes, as the shaders interpolate it: exact per segment.
        double avg = 0.0;
        for (int i = 0; i + 1 < n; ++i) {
            const double x0 = double(i) / (n - 1), x1 = double(i + 1) / (n - 1);
            const double e0 = table[j * n + i], e1 = table[j * n + i + 1];
            const double slope = (e1 - e0) / (x1 - x0);
            auto primitive = [&](double x) {
                const double x4 = x * x * x * x;
                return (e0 - slope * x0) * x4 / 4.0 + slope * x4 * x / 5.0;
            };
            avg += 4.0 * (primitive(x1) - primitive(x0));
        }
        table[n * n + j] = static_cast<float>(avg);
    }
    tables[key] = table;
    return table;
}

}  // namespace glslppm
