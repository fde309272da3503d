// Per-thread pseudorandom numbers in [0, 1), two generators behind one interface.
//
// Define exactly one of
//   RNG_PAPER  the paper's float-only generator GPURnd (Hachisuka 2015, Figure 4): four
//              multiplicative LCGs (L'Ecuyer 1988, Schrage's method) in float arithmetic,
//              state seeded per thread on the CPU (native/render/rng_seed.h), kept in an SSBO;
//   RNG_PCG    a PCG-RXS-M-XS-32 generator (O'Neill 2014), state hashed on the GPU from
//              (thread index, u_rng_seed); nothing uploaded, nothing stored.
// Call sites are identical for both:
//   RNG_STATE s = rng_load(thread_index);   // at the start of a kernel
//   float u = rng_next(s);                  // as often as needed
//   rng_store(thread_index, s);             // at the end (a no-op for RNG_PCG)
// With RNG_PCG the host sets `u_rng_seed` to a value unique per (pass, kernel).
// docs/rng.md compares the two (dieharder, speed).

#include "common/bindings.glsl"

#if defined(RNG_PAPER) && defined(RNG_PCG)
#error "rng.glsl: define exactly one of RNG_PAPER and RNG_PCG, not both"
#elif !defined(RNG_PAPER) && !defined(RNG_PCG)
#error "rng.glsl: define exactly one of RNG_PAPER and RNG_PCG"
#endif


#ifdef RNG_PAPER

#define RNG_STATE vec4

// Exactly as the paper's Figure 4 prints it. Every step is exact in float for integer-valued
// states below 2^22 (products < 2^24); only the final dot/fract rounds (docs/rng.md).
float GPURnd(inout vec4 state) {
  const vec4 q = vec4(1225, 1585, 2457, 2098);
  const vec4 r = vec4(1112, 367, 92, 265);
  const vec4 a = vec4(3423, 2646, 1707, 1999);
  const vec4 m = vec4(4194287, 4194277, 4194191, 4194167);

  vec4 beta = floor(state / q);
  vec4 p = a * mod(state, q) - beta * r;
  beta = (sign(-p) + vec4(1)) * vec4(0.5) * m;
  state = (p + beta);

  return fract(dot(state / m, vec4(1, -1, 1, -1)));
}

layout(std430, binding = BINDING_RNG_STATES) buffer RngStates {
  vec4 rng_states[];
};

RNG_STATE rng_load(uint thread_index) { return rng_states[thread_index]; }
void rng_store(uint thread_index, RNG_STATE s) { rng_states[thread_index] = s; }

// fract() of a tiny negative sum rounds to exactly 1.0 (about once in 5e7 draws); callers
// index arrays with u * n, so the largest float below 1 stands in for it.
float rng_next(inout RNG_STATE s) { return min(GPURnd(s), uintBitsToFloat(0x3F7FFFFFu)); }

#endif  // RNG_PAPER

#ifdef RNG_PCG

#define RNG_STATE uint

uniform uint u_rng_seed;

// PCG's LCG step and its RXS-M-XS output permutation (O'Neill 2014, pcg_output_rxs_m_xs_32_32).
uint rng_pcg_permute(uint state) {
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

// One LCG step then the permutation: the "PCG hash" of Jarzynski and Olano (JCGT 2020).
uint rng_pcg_hash(uint v) { return rng_pcg_permute(v * 747796405u + 2891336453u); }

// A thread's starting state, from its index and the kernel's seed. Hashing the index before
// adding the seed's hash keeps threads of different passes from sharing shifted streams.
RNG_STATE rng_load(uint thread_index) {
  return rng_pcg_hash(rng_pcg_hash(thread_index) + rng_pcg_hash(u_rng_seed ^ 0x9E3779B9u));
}
void rng_store(uint thread_index, RNG_STATE s) {}

// Output of the old state (as PCG does), top 24 bits as a float in [0, 1 - 2^-24].
float rng_next(inout RNG_STATE s) {
  uint old = s;
  s = old * 747796405u + 2891336453u;
  return float(rng_pcg_permute(old) >> 8u) * (1.0 / 16777216.0);
}

#endif  // RNG_PCG
