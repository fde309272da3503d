// Test program for the media's samplers (tests/native/media_probe_test.cpp): common/phase.glsl
// and common/equiangular.glsl. Not a pipeline stage.
//   u_mode 0: thread i draws one direction after arriving along u_arrived: (dir, hg_phase).
//   u_mode 1: thread i evaluates hg_phase at cos_theta = probe_in[i].x.
//   u_mode 2: thread i draws a distance on [u_t0, u_t1] of the ray (u_o, u_d) towards the
//             point u_c: (t, equiangular_pdf, 0, 0).
//   u_mode 3: thread i evaluates equiangular_pdf at t = probe_in[i].x.
layout(local_size_x = 64) in;

#include "common/frame.glsl"
#include "common/sampling.glsl"
#include "common/phase.glsl"
#include "common/equiangular.glsl"
#include "tests/probe_random.glsl"

layout(std430, binding = 20) readonly buffer ProbeIn { vec4 probe_in[]; };
layout(std430, binding = 21) writeonly buffer ProbeOut { vec4 probe_out[]; };

uniform uint u_mode;
uniform uint u_count;
uniform float u_g;
uniform vec3 u_arrived;
uniform uint u_seed;
uniform vec3 u_o, u_d, u_c;
uniform float u_t0, u_t1;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_count) return;
    if (u_mode == 0u) {
        uint s = probe_hash(i ^ probe_hash(u_seed));
        float u1 = probe_uniform(s), u2 = probe_uniform(s);
        vec3 dir = hg_sample(u_arrived, u_g, u1, u2);
        probe_out[i] = vec4(dir, hg_phase(dot(u_arrived, dir), u_g));
    } else if (u_mode == 1u) {
        probe_out[i] = vec4(hg_phase(probe_in[i].x, u_g), 0.0, 0.0, 0.0);
    } else {
        Equiangular e = equiangular_setup(u_o, u_d, u_c, u_t0, u_t1);
        float t = probe_in[i].x;
        if (u_mode == 2u) {
            uint s = probe_hash(i ^ probe_hash(u_seed));
            t = equiangular_sample(e, probe_uniform(s));
        }
        probe_out[i] = vec4(t, equiangular_pdf(e, t), 0.0, 0.0);
    }
}
