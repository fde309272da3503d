// Draws u_per_thread numbers per thread from rng.glsl, for tests and the PRNG benchmark.
//   default:          values[k * u_threads + t] = k-th number of thread t (threads
//                     interleaved, the order in which neighbouring pixels use them)
//   RNG_STREAM_SUM:   values[t] = sum of thread t's numbers (generation-only timing; the sum
//                     keeps the compiler from dropping the work)
//   RNG_STREAM_STATES also states[k * u_threads + t] = the state after the k-th draw
#include "common/rng.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 0) writeonly buffer Values {
  float values[];
};
#ifdef RNG_STREAM_STATES
layout(std430, binding = 1) writeonly buffer States {
  RNG_STATE states[];
};
#endif

uniform uint u_threads;
uniform uint u_per_thread;

void main() {
  uint t = gl_GlobalInvocationID.x;
  if (t >= u_threads) return;
  RNG_STATE s = rng_load(t);
#ifdef RNG_STREAM_SUM
  float sum = 0.0;
  for (uint k = 0u; k < u_per_thread; ++k) sum += rng_next(s);
  values[t] = sum;
#else
  for (uint k = 0u; k < u_per_thread; ++k) {
    values[k * u_threads + t] = rng_next(s);
#ifdef RNG_STREAM_STATES
    states[k * u_threads + t] = s;
#endif
  }
#endif
  rng_store(t, s);
}
