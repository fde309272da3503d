// Exact hashing's counting sort: an exclusive prefix sum of the cells' photon counts
// (hash_cells[].x) into their first sorted slots (hash_cells[].y), in three dispatches:
// PHASE_BLOCKS scans blocks of 1024 cells and writes each block's total after the sorted
// photons; PHASE_BLOCK_SUMS scans those totals in one work group; PHASE_ADD adds them back.
#define SCAN_THREADS 256u
#define CELLS_PER_THREAD 4u
#define CELLS_PER_BLOCK (SCAN_THREADS * CELLS_PER_THREAD)
layout(local_size_x = 256) in;

#define USES_HASH
#include "common/frame.glsl"
#include "common/sppm_buffers.glsl"

shared uint partial[SCAN_THREADS];

// Exclusive scan of partial[] across the work group (Hillis-Steele); returns the total.
uint scan_work_group(uint value) {
    uint t = gl_LocalInvocationID.x;
    partial[t] = value;
    barrier();
    for (uint offset = 1u; offset < SCAN_THREADS; offset <<= 1u) {
        uint add = t >= offset ? partial[t - offset] : 0u;
        barrier();
        partial[t] += add;
        barrier();
    }
    uint total = partial[SCAN_THREADS - 1u];
    uint exclusive = partial[t] - value;
    barrier();
    partial[t] = exclusive;
    barrier();
    return total;
}

void main() {
    uint t = gl_LocalInvocationID.x;
    uint block_sums = photon_threads;  // the block totals follow the sorted photons
#if defined(PHASE_BLOCKS)
    uint first = gl_WorkGroupID.x * CELLS_PER_BLOCK + t * CELLS_PER_THREAD;
    uint sum = 0u;
    for (uint k = 0u; k < CELLS_PER_THREAD; ++k) sum += hash_cells[first + k].x;
    uint total = scan_work_group(sum);
    uint running = partial[t];
    for (uint k = 0u; k < CELLS_PER_THREAD; ++k) {
        hash_cells[first + k].y = running;
        running += hash_cells[first + k].x;
    }
    if (t == 0u) hash_sorted[block_sums + gl_WorkGroupID.x] = total;
#elif defined(PHASE_BLOCK_SUMS)
    uint blocks = hash_cell_count / CELLS_PER_BLOCK;
    uint per_thread = (blocks + SCAN_THREADS - 1u) / SCAN_THREADS;
    uint first = t * per_thread;
    uint sum = 0u;
    for (uint k = 0u; k < per_thread && first + k < blocks; ++k)
        sum += hash_sorted[block_sums + first + k];
    scan_work_group(sum);
    uint running = partial[t];
    for (uint k = 0u; k < per_thread && first + k < blocks; ++k) {
        uint v = hash_sorted[block_sums + first + k];
        hash_sorted[block_sums + first + k] = running;
        running += v;
    }
#elif defined(PHASE_ADD)
    uint cell = gl_WorkGroupID.x * CELLS_PER_BLOCK + t * CELLS_PER_THREAD;
    uint offset = hash_sorted[block_sums + gl_WorkGroupID.x];
    for (uint k = 0u; k < CELLS_PER_THREAD; ++k) hash_cells[cell + k].y += offset;
#else
#error "prefix_sum.comp needs a PHASE_ define"
#endif
}
