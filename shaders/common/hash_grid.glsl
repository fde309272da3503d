// The photon hash grid: cells of the size of the largest radius in use, so that a query
// of radius R around x only needs the 27 cells around x's cell; cells hash into a table.
#ifndef HASH_GRID_GLSL
#define HASH_GRID_GLSL

// The cell size this pass. SPPM: the largest radius after the last pass, which end_pass
// leaves in the counters on the GPU. PPPM: the pass's own radius, from the frame, so that
// no host write to a buffer the shaders write comes between passes. VCM's merging too.
float hash_cell_size() {
#if defined(ESTIMATOR_PPPM) || defined(ESTIMATOR_VCM)
    return pass_radius;
#else
    return uintBitsToFloat(cell_size_bits);
#endif
}

ivec3 grid_cell(vec3 p, float cell_size) {
    return ivec3(floor((p - scene_lo) / cell_size));
}

// A well-mixed hash of the cell (PCG-style integer mixing, Jarzynski and Olano 2020).
uint grid_hash(ivec3 c) {
    uvec3 v = uvec3(c) * 1664525u + 1013904223u;
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v ^= v >> 16u;
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    return (v.x ^ v.y ^ v.z) & (hash_cell_count - 1u);
}

#endif
