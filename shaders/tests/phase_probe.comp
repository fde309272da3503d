// Test program for common/phase.glsl (tests/native/phase_probe_test.cpp). Not a pipeline
// stage.
//   u_mode 0: thread i draws one direction after arriving along u_arrived: (dir, hg_phase).
//   u_mode 1: thread i evaluates hg_phase at cos_theta = probe_in[i].x.
layout(local_size_x = 64) in;

#include "common/frame.glsl"
#include "common/sampling.glsl"
#include "common/phase.glsl"
#include "tests/probe_random.glsl"

layout(std430, binding = 20) readonly buffer ProbeIn { vec4 probe_in[]; };
layout(std430, binding = 21) writeonly buffer ProbeOut { vec4 probe_out[]; };

uniform uint u_mode;
uniform uint u_count;
uniform float u_g;
uniform vec3 u_arrived;
uniform uint u_seed;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_count) return;
    if (u_mode == 0u) {
        uint s = probe_hash(i ^ probe_hash(u_seed));
        float u1 = probe_uniform(s), u2 = probe_uniform(s);
        vec3 dir = hg_sample(u_arrived, u_g, u1, u2);
        probe_out[i] = vec4(dir, hg_phase(dot(u_arrived, dir), u_g));
    } else {
        probe_out[i] = vec4(hg_phase(probe_in[i].x, u_g), 0.0, 0.0, 0.0);
    }
}
