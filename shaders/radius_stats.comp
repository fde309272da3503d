// The radii's sum and maximum over all pixels, for stats(): one work group, each thread
// summing every LOCAL_SIZE-th pixel with Kahan compensation, so that the host reads back one
// (sum, max) pair per thread instead of every pixel's statistics.
layout(local_size_x = RADIUS_STATS_THREADS) in;

#define USES_PIXEL_STATE
#include "common/frame.glsl"
#include "common/sppm_buffers.glsl"

layout(std430, binding = BINDING_RADIUS_STATS) writeonly buffer RadiusStats {
    vec2 radius_stats[];  // per thread: (sum of its pixels' radii, their largest)
};

void main() {
    uint t = gl_LocalInvocationID.x;
    uint n = image_width * image_height;
    precise float sum = 0.0;
    precise float comp = 0.0;
    float largest = 0.0;
    for (uint i = t; i < n; i += RADIUS_STATS_THREADS) {
        float r = pixel_stats[2u * i + 1u].x;
        precise float y = r - comp;
        precise float s = sum + y;
        comp = (s - sum) - y;
        sum = s;
        largest = max(largest, r);
    }
    radius_stats[t] = vec2(sum, largest);
}
