// Test program for common/camera.glsl (tests/native/camera_ray_probe_test.cpp): per film
// point, the camera ray eye_trace.comp casts through it, so that the test can hold it to the
// CPU's (native/render/camera_ray.cpp). Not a pipeline stage. Define HAS_DEPTH_OF_FIELD for
// the thin lens, as the renderer's programs would.
layout(local_size_x = 64) in;

#include "common/frame.glsl"
#include "common/sampling.glsl"
#include "common/camera.glsl"

// Per point: (pixel x + jx, pixel y + jy, lens u1, lens u2).
layout(std430, binding = 3) readonly buffer Points { vec4 probe_points[]; };
// Per point: (origin, 0), (direction, 0): the direction before eye_trace normalizes it.
layout(std430, binding = 4) writeonly buffer Probe { vec4 probe_out[]; };

uniform uint u_count;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_count) return;
    vec4 p = probe_points[i];
    vec3 origin, dir;
    camera_ray_at(p.xy, p.zw, origin, dir);
    probe_out[2u * i] = vec4(origin, 0.0);
    probe_out[2u * i + 1u] = vec4(dir, 0.0);
}
