// Light linking and shadow linking (Blender 4.0+'s Object > Shading > Light Linking and Shadow
// Linking; docs/light_linking.md). Every emitter has a link set s (emitter_link_set,
// common/scene_buffers.glsl; the world's is 0), every material a row r (above its group code
// in MATERIAL_ABSORPTION's w). Bit s of LIGHT_LINK_RECEIVES[r] says that the emitter's light
// reaches the material, bit s of SHADOW_LINK_BLOCKS[r] that the material shadows it:
// - a light sample from an emitter whose light does not reach the point adds nothing, and its
//   shadow ray passes the surfaces that do not shadow that emitter (shadow_passes,
//   common/light_sampling.glsl); so does a BSDF sample's emission (light_along_bsdf_sample);
// - a photon keeps its emitter's set (photon_link_code, common/sppm_buffers.glsl) until it
//   lands on a surface a visible point may gather it on: there it is absorbed, neither stored
//   nor going on, unless its emitter's light reaches that surface; before that it passes
//   the surfaces that do not shadow its emitter. So a caustic (light, glass, receiver) lands
//   only on receivers its light reaches, and light scattered once is free of links, as in
//   Cycles, where the link is checked at the receiving shading point;
// - emission the eye path meets after a mirror or glass counts only where the emitter's light
//   reaches the surface it last scattered from (eye_link_reaches).
// Nothing here is compiled without links (the specialization row `light-linking`).
#ifndef LIGHT_LINKING_GLSL
#define LIGHT_LINKING_GLSL
#include "common/scene_buffers.glsl"
#ifdef LIGHT_LINKING

const uint light_link_receives[LIGHT_LINK_ROWS] = uint[](LIGHT_LINK_RECEIVES);
const uint shadow_link_blocks[LIGHT_LINK_ROWS] = uint[](SHADOW_LINK_BLOCKS);
// A link set no emitter has: every surface shadows it (the BSDF samples' rays).
const uint LINK_SET_ANY = uint(MAX_LIGHT_LINK_SETS);

uint material_link_row(int m) {
    return (uint(material_record(m, MATERIAL_ABSORPTION).w) / uint(MATERIAL_LINK_ROW_SCALE)) %
           uint(MAX_LIGHT_LINK_ROWS);
}

// The link set of material m's emission (Material::light_link_set).
uint material_link_set(int m) {
    return uint(material_record(m, MATERIAL_ABSORPTION).w) / uint(MATERIAL_LINK_SET_SCALE);
}

// Whether light of link set `set` reaches material m.
bool light_link_reaches(uint set, int m) {
    return ((light_link_receives[material_link_row(m)] >> set) & 1u) != 0u;
}

// Whether material m shadows light of link set `set` (LINK_SET_ANY: always).
bool shadow_link_blocks_set(int m, uint set) {
    return set >= LINK_SET_ANY || ((shadow_link_blocks[material_link_row(m)] >> set) & 1u) != 0u;
}

// The link set the shadow ray being traced is for (read by shadow_passes), and the material
// the light samples are for (read by light_along_bsdf_sample).
uint shadow_link_set = LINK_SET_ANY;
int light_link_receiver = 0;

#ifdef USES_EMITTERS
// A light sample from emitter `picked` for material m: nothing where its light does not reach
// m; its shadow ray passes what does not shadow it.
void light_link_sample(int m, uint picked, inout vec3 radiance_over_pdf) {
    uint set = emitter_link_set(picked);
    if (!light_link_reaches(set, m)) radiance_over_pdf = vec3(0.0);
    light_link_receiver = m;
    shadow_link_set = set;
}
#endif

// The eye path's receiver of the emission it meets: as in Cycles (the object the last BSDF
// sample left, the forward receiver), the root material of the surface it last scattered
// from (a mirror, glass); -1 while the camera sees the path directly: the camera is no
// receiver, so emitters seen directly are not linked. Set by eye_trace.comp; read by
// eye_link_reaches and by hit_sphere_light (common/sphere_lights.glsl), which, as Cycles'
// light intersection, passes over the sphere lights that do not reach it.
int eye_link_receiver = -1;

// Whether emission of link set `set` met by the eye path counts.
bool eye_link_reaches(uint set) {
    return eye_link_receiver < 0 || light_link_reaches(set, eye_link_receiver);
}

#ifdef USES_PHOTON_PATHS
// A photon's surface: whether it goes through, as the light's shadow rays would (its emitter
// not shadowed by m), while it still carries its emitter's set.
bool photon_link_passes(int m) {
    return photon_link_code > 0u && !shadow_link_blocks_set(m, photon_link_code - 1u);
}

// At a surface where a visible point may gather the photon (`gathered`): whether its light
// reaches it; there the photon lets go of its emitter's set.
bool photon_link_lands(int m, bool gathered) {
    if (photon_link_code == 0u || !gathered) return true;
    bool reaches = light_link_reaches(photon_link_code - 1u, m);
    photon_link_code = 0u;
    return reaches;
}
#endif

#endif
#endif
