#include "render/environment_map.h"

#include <algorithm>
#include <cmath>

namespace glslppm {
namespace {

constexpr double kPi = 3.14159265358979323846;

float luminance(glm::vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

}  // namespace

float srgb_to_linear(std::uint8_t value) {
    const double c = value / 255.0;
    return static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
}

glm::vec3 texel_rgb(const Texture& texture, int x, int y) {
    const std::size_t i = 4 * (static_cast<std::size_t>(y) * texture.width + x);
    if (!texture.linear.empty())
        return {texture.linear[i], texture.linear[i + 1], texture.linear[i + 2]};
    return {srgb_to_linear(texture.srgb8[i]), srgb_to_linear(texture.srgb8[i + 1]),
            srgb_to_linear(texture.srgb8[i + 2])};
}

EnvironmentMap build_environment_map(const Texture& texture, glm::vec3 color) {
    // Pool texels so the distribution stays at most 2048 x 1024.
    const int pool = std::max(1, std::max((texture.width + 2047) / 2048,
                                          (texture.height + 1023) / 1024));
    EnvironmentMap map;
    map.width = (texture.width + pool - 1) / pool;
    map.height = (texture.height + pool - 1) / pool;
    const int w = map.width, h = map.height;

    // Mean radiance per pooled texel (for the integral) and its luminance.
    std::vector<glm::vec3> radiance(static_cast<std::size_t>(w) * h, glm::vec3(0.0f));
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            glm::dvec3 sum(0.0);
            int n = 0;
            for (int yy = y * pool; yy < std::min(texture.height, (y + 1) * pool); ++yy)
                for (int xx = x * pool; xx < std::min(texture.width, (x + 1) * pool); ++xx, ++n)
                    sum += glm::dvec3(texel_rgb(texture, xx, yy));
            radiance[static_cast<std::size_t>(y) * w + x] = glm::vec3(sum / double(n)) * color;
        }
    }
    // Weights: the largest luminance of the texel and its neighbours (wrapping in u,
    // clamped in v), times sin(theta) at the row's centre.
    std::vector<double> weight(radiance.size());
    glm::dvec3 integral(0.0);
    for (int y = 0; y < h; ++y) {
        const double sin_theta = std::sin(kPi * (y + 0.5) / h);
        for (int x = 0; x < w; ++x) {
            float m = 0.0f;
            for (int dy = -1; dy <= 1; ++dy) {
                const int yy = std::clamp(y + dy, 0, h - 1);
                for (int dx = -1; dx <= 1; ++dx) {
                    const int xx = (x + dx + w) % w;
                    m = std::max(m, luminance(radiance[static_cast<std::size_t>(yy) * w + xx]));
                }
            }
            weight[static_cast<std::size_t>(y) * w + x] = std::max(0.0f, m) * sin_theta;
            // Texel solid angle: (2 pi / w) * (pi / h) * sin(theta).
            integral += glm::dvec3(radiance[static_cast<std::size_t>(y) * w + x]) *
                        (2.0 * kPi * kPi * sin_theta / (double(w) * h));
        }
    }
    map.integral = glm::vec3(integral);

    map.cdf.assign(static_cast<std::size_t>(h + 1) + static_cast<std::size_t>(h) * (w + 1), 0.0f);
    std::vector<double> row_sum(h, 0.0);
    for (int y = 0; y < h; ++y) {
        float* row = &map.cdf[static_cast<std::size_t>(h + 1) + static_cast<std::size_t>(y) * (w + 1)];
        double running = 0.0;
        for (int x = 0; x < w; ++x) running += weight[static_cast<std::size_t>(y) * w + x];
        row_sum[y] = running;
        double acc = 0.0;
        for (int x = 0; x < w; ++x) {
            row[x] = running > 0 ? static_cast<float>(acc / running) : static_cast<float>(x) / w;
            acc += weight[static_cast<std::size_t>(y) * w + x];
        }
        row[w] = 1.0f;
    }
    double total = 0.0;
    for (double s : row_sum) total += s;
    double acc = 0.0;
    for (int y = 0; y < h; ++y) {
        map.cdf[y] = total > 0 ? static_cast<float>(acc / total) : static_cast<float>(y) / h;
        acc += row_sum[y];
    }
    map.cdf[h] = 1.0f;
    return map;
}

}  // namespace glslppm
