#include "render/camera_ray.h"

#include <cmath>

namespace glslppm {

glm::vec2 sample_disc(float u1, float u2) {
    constexpr float kPi = 3.14159265358979f;  // frame.glsl's PI
    const float a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f;
    if (a == 0.0f && b == 0.0f) return glm::vec2(0.0f);
    float r, phi;
    if (std::abs(a) > std::abs(b)) {
        r = a;
        phi = (kPi / 4.0f) * (b / a);
    } else {
        r = b;
        phi = (kPi / 2.0f) - (kPi / 4.0f) * (a / b);
    }
    return r * glm::vec2(std::cos(phi), std::sin(phi));
}

Ray camera_ray_at(const FrameBlock& f, glm::vec2 pixel, glm::vec2 lens_u, bool depth_of_field) {
    // Film coordinates in [-1, 1], y up; row 0 is the top of the image.
    const glm::vec2 ndc(2.0f * pixel.x / static_cast<float>(f.image_width) - 1.0f,
                        1.0f - 2.0f * pixel.y / static_cast<float>(f.image_height));
    const glm::vec2 film = ndc * f.film_half_extent + f.film_shift;
    glm::vec3 origin, dir;
    if (f.orthographic != 0u) {
        origin = glm::vec3(film, 0.0f);
        dir = glm::vec3(0.0f, 0.0f, -1.0f);
    } else {
        origin = glm::vec3(0.0f);
        dir = glm::vec3(film, -1.0f);
        if (depth_of_field) {
            // Thin lens: rays through the lens disc meet on the plane at the focus distance.
            const glm::vec3 focus = dir * f.focus_distance;
            const glm::vec2 lens = f.aperture_radius * sample_disc(lens_u.x, lens_u.y);
            origin = glm::vec3(lens, 0.0f);
            dir = focus - origin;
        }
    }
    Ray ray;
    ray.origin = glm::vec3(f.camera_to_world * glm::vec4(origin, 1.0f));
    ray.dir = glm::vec3(f.camera_to_world * glm::vec4(dir, 0.0f));
    return ray;
}

}  // namespace glslppm
