// The camera ray through a point of the film, from the Frame's camera fields; mirrored by
// native/render/camera_ray.cpp (the automatic radius looks through it) and held to it by
// tests/native/camera_ray_probe_test.cpp. Include after common/frame.glsl and
// common/sampling.glsl.
#ifndef CAMERA_GLSL
#define CAMERA_GLSL

// pixel: the point in the image's pixels (x + jx, y + jy; row 0 at the top). lens_u: two
// numbers in [0, 1) for the point on the lens, read with HAS_DEPTH_OF_FIELD only. The
// direction is not normalized.
void camera_ray_at(vec2 pixel, vec2 lens_u, out vec3 origin, out vec3 dir) {
    // Film coordinates in [-1, 1], y up; row 0 is the top of the image.
    vec2 ndc = vec2(2.0 * pixel.x / float(image_width) - 1.0,
                    1.0 - 2.0 * pixel.y / float(image_height));
    vec2 film = ndc * film_half_extent + film_shift;
    if (orthographic != 0u) {
        origin = vec3(film, 0.0);
        dir = vec3(0.0, 0.0, -1.0);
    } else {
        origin = vec3(0.0);
        dir = vec3(film, -1.0);
#ifdef HAS_DEPTH_OF_FIELD
        // Thin lens: rays through the lens disc meet on the plane at the focus distance.
        vec3 focus = dir * focus_distance;
        vec2 lens = aperture_radius * sample_disc(lens_u.x, lens_u.y);
        origin = vec3(lens, 0.0);
        dir = focus - origin;
#endif
    }
    origin = (camera_to_world * vec4(origin, 1.0)).xyz;
    dir = (camera_to_world * vec4(dir, 0.0)).xyz;
}

#endif
