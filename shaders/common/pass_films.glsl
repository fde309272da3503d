// Render passes beside Combined (native/render/render_passes.h, docs/passes.md). Each enabled
// pass has a (sum, compensation) pair of vec4 in a pixel's record of PASS_STRIDE vec4, at the
// offset its define names (PASS_DEPTH, ...); Direct with photon direct light has a second
// pair for its photons. Nothing here is compiled without passes.
#ifndef PASS_FILMS_GLSL
#define PASS_FILMS_GLSL
#ifdef PASS_STRIDE
#include "common/bindings.glsl"
#include "common/compensated_sum.glsl"

layout(std430, binding = BINDING_PASS_FILMS) buffer PassFilms { vec4 pass_films[]; };

// The classes of photon paths (PASS_PHOTON_SPLIT), kept in the path's flux.w and the stored
// photon's direction.w: straight from a light; scattered, diffusely or by rough lobes only;
// through at least one bounce an eye path would follow (a caustic).
const float PHOTON_PATH_DIRECT = 0.0;
const float PHOTON_PATH_INDIRECT = 1.0;
const float PHOTON_PATH_CAUSTIC = 2.0;

uint pass_record(uint pixel, uint offset) { return pixel * PASS_STRIDE + offset; }

// Adds one pass's sample to its compensated sum.
void pass_add(uint pixel, uint offset, vec4 value) {
    uint k = pass_record(pixel, offset);
    vec4 sum = pass_films[k], compensation = pass_films[k + 1u];
    kahan_add(sum, compensation, value);
    pass_films[k] = sum;
    pass_films[k + 1u] = compensation;
}

#endif
#endif
