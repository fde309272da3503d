// Light tracing's end of pass (HAS_LIGHT_TRACING), one thread per pixel: the pass's
// fixed-point splats (common/light_splats.glsl) into the pixel's compensated float sum, the
// integers cleared for the next pass. SPPM: the film adds sum / N_emitted (resolve_film.comp),
// the same normalisation as its tau: photon paths span passes, so the passes' splats are
// divided by every path started, not averaged pass by pass. PPPM: every pass starts one path
// per photon thread, so each pass's splats are divided by its own paths here and the film
// takes their mean, as its tau: a pass is a function of its index alone.
layout(local_size_x = LOCAL_SIZE) in;

#define USES_LIGHT_SPLATS

#include "common/frame.glsl"
#include "common/compensated_sum.glsl"
#include "common/light_splats.glsl"

void main() {
    uint i = thread_index();
    if (i >= image_width * image_height) return;
    uint k = i * LIGHT_SPLAT_WORDS;
    vec4 sum = vec4(light_splat_word3(k + LIGHT_SPLAT_SUM), 0.0);
    vec4 compensation = vec4(light_splat_word3(k + LIGHT_SPLAT_COMPENSATION), 0.0);
#if defined(ESTIMATOR_PPPM) || defined(ESTIMATOR_VCM)
    kahan_add(sum, compensation, vec4(light_splat_pass(i) / float(photon_threads), 0.0));
#else
    kahan_add(sum, compensation, vec4(light_splat_pass(i), 0.0));
#endif
    for (uint w = 0u; w < 3u; ++w) {
        light_splats[k + LIGHT_SPLAT_SUM + w] = floatBitsToUint(sum[w]);
        light_splats[k + LIGHT_SPLAT_COMPENSATION + w] = floatBitsToUint(compensation[w]);
    }
    for (uint w = 0u; w < 6u; ++w) light_splats[k + w] = 0u;
#ifdef LIGHT_GROUPS
    // Each group's splats (common/light_splats.glsl) folded the same way.
    // A group no splat reached here this pass (most pixels: splats land on caustics) is
    // left as it is, its sum and compensation unread and unwritten: an H100 spent about
    // 0.37 ms a pass per group of a 1080p frame folding them all.
    for (uint g = 0u; g < uint(LIGHT_GROUPS); ++g) {
        uint kg = light_splat_group_word(i, g);
        if ((light_splats[kg] | light_splats[kg + 1u] | light_splats[kg + 2u] |
             light_splats[kg + 3u] | light_splats[kg + 4u] | light_splats[kg + 5u]) == 0u)
            continue;
        vec4 group_sum = vec4(light_splat_word3(kg + LIGHT_SPLAT_SUM), 0.0);
        vec4 group_compensation = vec4(light_splat_word3(kg + LIGHT_SPLAT_COMPENSATION), 0.0);
#if defined(ESTIMATOR_PPPM) || defined(ESTIMATOR_VCM)
        kahan_add(group_sum, group_compensation,
                  vec4(light_splat_pass_at(kg) / float(photon_threads), 0.0));
#else
        kahan_add(group_sum, group_compensation, vec4(light_splat_pass_at(kg), 0.0));
#endif
        for (uint w = 0u; w < 3u; ++w) {
            light_splats[kg + LIGHT_SPLAT_SUM + w] = floatBitsToUint(group_sum[w]);
            light_splats[kg + LIGHT_SPLAT_COMPENSATION + w] =
                floatBitsToUint(group_compensation[w]);
        }
        for (uint w = 0u; w < 6u; ++w) light_splats[kg + w] = 0u;
    }
#endif
}
