// Test program for common/lobes.glsl (tests/native/bsdf_probe_test.cpp): the lobes the
// renderer's stages use, on a surface at the origin with unit normal u_n (+z unless a test
// tilts it, so that the shading frame's rotations round as a mesh's do), seen from u_wo. Not
// a pipeline stage.
//   u_mode 0: thread i draws one sample: (wi, 1 if drawn), (weight = f cos / pdf, bsdf_pdf).
//   u_mode 1: thread i evaluates the direction probe_in[i]: (f, bsdf_pdf), (f(wi, wo) with
//             the roles exchanged, 0): reciprocity.
layout(local_size_x = 64) in;

#include "common/frame.glsl"
#include "common/lobes.glsl"
#include "tests/probe_random.glsl"

layout(std430, binding = 20) readonly buffer ProbeIn { vec4 probe_in[]; };
layout(std430, binding = 21) writeonly buffer ProbeOut { vec4 probe_out[]; };

uniform uint u_mode;
uniform uint u_count;
uniform int u_material;
uniform vec3 u_wo;
uniform vec3 u_n;
uniform uint u_seed;
uniform uint u_adjoint;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= u_count) return;
    vec3 n = u_n;
    uint s = probe_hash(i ^ probe_hash(u_seed));
    TexturePoint at = TexturePoint(vec2(0.0), vec3(0.0));
    Shading sh = shading_at(u_material, n, n, at, vec3(1.0), u_wo, probe_uniform(s));
    if (u_mode == 0u) {
        vec3 u = vec3(probe_uniform(s), probe_uniform(s), probe_uniform(s));
        vec3 wi, weight;
        bool ok = bsdf_sample(sh, u_wo, u, u_adjoint != 0u, wi, weight);
        float pdf = ok ? bsdf_pdf(sh, u_wo, wi) : 0.0;
        probe_out[2u * i] = vec4(wi, ok ? 1.0 : 0.0);
        probe_out[2u * i + 1u] = vec4(weight, pdf);
    } else {
        vec3 wi = probe_in[i].xyz;
        vec3 f = bsdf_f(sh, u_wo, wi, false, false);
        Shading back = shading_at(u_material, n, n, at, vec3(1.0), wi, 0.5);
        vec3 f_swapped = bsdf_f(back, wi, u_wo, false, false);
        probe_out[2u * i] = vec4(f, bsdf_pdf(sh, u_wo, wi));
        probe_out[2u * i + 1u] = vec4(f_swapped, 0.0);
    }
}
