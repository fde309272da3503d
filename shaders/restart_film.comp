// A film's first state, at a new renderer and at every restart (a camera move, a material
// edit, reset_film): no passes, every pixel's radius the initial one, no direct light,
// every photon path to start from a light, the pass counters zero. One thread per pixel
// and per photon thread, on the GPU, so that a viewport restart uploads nothing (filling
// 32 bytes per pixel on the host took most of a 1920x1080 restart).
layout(local_size_x = LOCAL_SIZE) in;

#define USES_PIXEL_STATE
#define USES_PHOTON_PATHS
#include "common/frame.glsl"
#include "common/sppm_buffers.glsl"

uniform uint u_pixels;          // this renderer's pixels (a tile's, when tiled)
uniform uint u_photon_threads;  // photon paths, one per photon thread
uniform float u_initial_radius;

void main() {
    uint i = thread_index();
    if (i < u_pixels) {
        pixel_stats[2 * i + 0] = vec4(0.0);                          // tau, N
        pixel_stats[2 * i + 1] = vec4(u_initial_radius, 0.0, 0.0, 0.0);  // R
        direct_light[2 * i + 0] = vec4(0.0);
        direct_light[2 * i + 1] = vec4(0.0);
    }
    if (i < u_photon_threads) {
        // Start anew from a light.
        store_photon_path_record(i, PHOTON_PATH_ORIGIN, vec4(0.0, 0.0, 0.0, -1.0));
        store_photon_path_record(i, PHOTON_PATH_DIR, vec4(0.0));
        store_photon_path_record(i, PHOTON_PATH_FLUX, vec4(0.0));
    }
    if (i == 0u) {
        cell_size_bits = floatBitsToUint(u_initial_radius);
        max_radius_bits = 0u;
        pass_emitted = 0u;
        pass_rays = 0u;
        emitted_lo = 0u;
        emitted_hi = 0u;
        rays_lo = 0u;
        rays_hi = 0u;
    }
}
