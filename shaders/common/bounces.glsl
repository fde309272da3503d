// Cycles' Light Paths limits on a full SPPM path (docs/bounces.md). Cycles' path_state_next
// (kernel/integrator/path_state.h) counts every scatter once in the total and once in its
// kind: a reflection is diffuse or glossy (mirrors, glass's reflection and total internal
// reflection are glossy), any transmission is transmission (refraction and translucency); a
// cut-out counts in none. Its kernel limits are the settings plus one and a path reaching one
// is cut after its next surface's emission, so a path's light counts while the scatters
// before its last one (the one towards the light) are within every limit: 0 keeps direct
// light only.
//
// An SPPM path is camera, eye scatters, the visible point, the photon's scatters, light. The
// photon's first scatter (nearest the light) is that last one and is left out; so is the
// visible point's where the photon came straight from the light. What is counted lives in
// one word: three 7-bit counts (saturating at 127: limits above 126 are unlimited in their
// kind, the total still cut by the hit counts of both subpaths) and, for photons, a bit
// saying the path has had its first scatter. Below 2^22, the word rides exactly in a float.
#ifndef BOUNCES_GLSL
#define BOUNCES_GLSL

const uint BOUNCE_DIFFUSE = 0u;
const uint BOUNCE_GLOSSY = 1u;
const uint BOUNCE_TRANSMISSION = 2u;
const uint BOUNCE_NONE = 3u;  // a cut-out, passed through
const uint BOUNCES_SCATTERED = 1u << 21;

// A scatter's kind from the sides of wo and wi (a transmission crosses the surface) and
// whether the lobe drawn was diffuse.
uint bounce_kind(vec3 wo, vec3 wi, vec3 n, bool diffuse_lobe) {
    if (dot(wo, n) * dot(wi, n) < 0.0) return BOUNCE_TRANSMISSION;
    return diffuse_lobe ? BOUNCE_DIFFUSE : BOUNCE_GLOSSY;
}

// The rest reads the frame's limits: programs without the Frame block (the BSDF probe) take
// only the kinds above.
#ifdef FRAME_GLSL
uint bounce_count(uint word, uint kind) {
    return (word >> (7u * kind)) & 127u;
}

uint bounces_add(uint word, uint kind) {
    return kind < BOUNCE_NONE && bounce_count(word, kind) < 127u ? word + (1u << (7u * kind))
                                                                  : word;
}

// The counts of both words (kind by kind, saturating); the flags of the first.
uint bounces_sum(uint a, uint b) {
    uint word = a;
    for (uint kind = 0u; kind < BOUNCE_NONE; ++kind)
        word += min(bounce_count(b, kind), 127u - bounce_count(word, kind)) << (7u * kind);
    return word;
}

uint bounces_total(uint word) {
    return bounce_count(word, BOUNCE_DIFFUSE) + bounce_count(word, BOUNCE_GLOSSY) +
           bounce_count(word, BOUNCE_TRANSMISSION);
}

// Whether counts within every limit of the frame (common/frame.glsl).
bool bounces_within(uint word) {
    return bounce_count(word, BOUNCE_DIFFUSE) <= max_diffuse_bounces &&
           bounce_count(word, BOUNCE_GLOSSY) <= max_glossy_bounces &&
           bounce_count(word, BOUNCE_TRANSMISSION) <= max_transmission_bounces &&
           bounces_total(word) <= max_bounces;
}

// A photon's first scatter is the full path's last: it only marks the word.
uint photon_bounces_scattered(uint word, uint kind) {
    if (kind == BOUNCE_NONE) return word;
    return (word & BOUNCES_SCATTERED) == 0u ? word | BOUNCES_SCATTERED : bounces_add(word, kind);
}

// The kinds of the visible point's scatter a photon may be gathered through (bit per kind),
// given the eye subpath's counts: all where the photon came straight from the light (the
// point's scatter is then the last), else those that keep the sum within every limit.
uint gather_bounce_kinds(uint eye, uint photon) {
    if ((photon & BOUNCES_SCATTERED) == 0u) return 7u;
    uint both = bounces_sum(eye, photon);
    uint kinds = 0u;
    for (uint kind = 0u; kind < BOUNCE_NONE; ++kind)
        if (bounces_within(bounces_add(both, kind))) kinds |= 1u << kind;
    return kinds;
}

// Whether a photon with this word can still light a visible point: through one kind at
// least of the point's own scatter, with nothing on the eye side.
bool photon_bounces_useful(uint word) {
    return gather_bounce_kinds(0u, word) != 0u;
}
#endif

#endif
