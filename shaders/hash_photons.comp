// SPPM stage 3, one thread per photon: hash this pass's photons into the grid.
// Stochastic (Hachisuka and Jensen 2010, with the paper's random depth): each cell keeps
// the photon with the smallest independent random key (atomicMin, the paper's z-buffer) and
// counts the photons that fell into it; the gather scales the survivor by that count.
// Exact: a counting sort keeps every photon (PHASE_COUNT, prefix_sum.comp, PHASE_SCATTER).
layout(local_size_x = LOCAL_SIZE) in;

#define USES_PHOTONS
#define USES_HASH
#include "common/frame.glsl"
#include "common/sppm_buffers.glsl"
#include "common/hash_grid.glsl"

#if defined(PHASE_CLEAR)
// One thread per cell: empty (stochastic: key "infinite", no photons; exact: no photons).
// A dispatch rather than glClearBufferData, so that a pass orders it after the last pass's
// shader writes with a storage barrier alone: the buffer-update barrier a clear needs made
// the NVIDIA driver wait on the host for the GPU every pass.
void main() {
    uint i = thread_index();
    if (i >= hash_cell_count) return;
#if defined(HASH_EXACT)
    hash_cells[i] = uvec4(0u);
#else
    hash_cells[i] = uvec4(0xFFFFFFFFu, 0u, 0u, 0u);
#endif
}
#else
void main() {
    uint i = thread_index();
    if (i >= photon_threads || photon_record(i, PHOTON_FLUX).w == 0.0) return;
    vec4 pk = photon_record(i, PHOTON_POSITION);
    uint h = grid_hash(grid_cell(pk.xyz, hash_cell_size()));
#if defined(PHASE_INSERT)
    atomicMin(hash_cells[h].x, floatBitsToUint(pk.w));
    atomicAdd(hash_cells[h].y, 1u);
#elif defined(PHASE_WINNER)
    // Equal keys (chance 2^-32 per pair) leave one of them, which is as good.
    if (hash_cells[h].x == floatBitsToUint(pk.w)) hash_cells[h].z = i;
#elif defined(PHASE_COUNT)
    atomicAdd(hash_cells[h].x, 1u);
#elif defined(PHASE_SCATTER)
    hash_sorted[hash_cells[h].y + atomicAdd(hash_cells[h].z, 1u)] = i;
#else
#error "hash_photons.comp needs a PHASE_ define"
#endif
}
#endif
