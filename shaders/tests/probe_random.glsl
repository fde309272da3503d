// Independent uniform numbers per thread for the test programs (a PCG step and an output
// permutation): the stream of thread i starts at probe_hash(i ^ probe_hash(seed)).
#ifndef PROBE_RANDOM_GLSL
#define PROBE_RANDOM_GLSL

uint probe_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

float probe_uniform(inout uint s) {
    s = probe_hash(s);
    return float(s >> 8) * (1.0 / 16777216.0);
}

#endif
