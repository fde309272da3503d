// Closes a pass in one thread: the next pass's hash cells take the largest radius now in
// use, and the pass counters go into 64-bit totals (photon counts pass 2^32 in long runs).
layout(local_size_x = 1) in;

#include "common/frame.glsl"
#include "common/sppm_buffers.glsl"

void add64(inout uint lo, inout uint hi, uint value) {
    uint carry;
    lo = uaddCarry(lo, value, carry);
    hi += carry;
}

void main() {
    cell_size_bits = max_radius_bits;
    max_radius_bits = 0u;
    add64(emitted_lo, emitted_hi, pass_emitted);
    add64(rays_lo, rays_hi, pass_rays);
    pass_emitted = 0u;
    pass_rays = 0u;
}
