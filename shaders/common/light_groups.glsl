// Light groups (Blender's View Layer > Light Groups; docs/light_groups.md): each group's light
// in a Combined-like pass of its own, which with the light of no group sums to Combined.
// Every emitter knows its group's code, the group + 1 (0: none): an emitter record's kind
// word (emitter_group_code, common/scene_buffers.glsl), an emissive material's absorption
// record's w (material_group_code) and the world's WORLD_LIGHT_GROUP. Photons carry their
// emitter's code from emission on (common/sppm_buffers.glsl: the path's flux.w, the stored
// photon's record word) and the gather adds each photon into its group's tau as well
// (gather.comp). The eye stage keeps this sample's light per group here: emission and the
// world where the path meets them, and the light samples' parts, which
// direct_light_sampled_lobes hands over (light_group_sampled_add).
//
// A group's record in the pass films (native/render/render_passes.h, PassLayout): from
// LIGHT_GROUP_FIRST + 4 group, the eye stage's (sum, compensation) and the photons' tau
// (and, with PPPM, its compensation). Nothing here is compiled without groups.
#ifndef LIGHT_GROUPS_GLSL
#define LIGHT_GROUPS_GLSL
// Outside the #ifdef: the include splicer takes a file where it first appears, #ifdef or not.
#include "common/bindings.glsl"
#include "common/compensated_sum.glsl"
#include "common/pass_films.glsl"
#ifdef LIGHT_GROUPS

const uint WORLD_GROUP_CODE = uint(WORLD_LIGHT_GROUP + 1);
// light_group_add's code for the light sample's parts (added by light_group_sampled_add).
const uint LIGHT_GROUP_SAMPLED = 0xFFFFFFFFu;

// Below the material's light link row (common/records.glsl).
uint material_group_code(int m) {
    return uint(material_record(m, MATERIAL_ABSORPTION).w) % uint(MATERIAL_LINK_ROW_SCALE);
}

uint light_group_record(uint group) { return LIGHT_GROUP_FIRST + 4u * group; }

#ifdef USES_PIXEL_STATE
// This eye sample's light per group. The light sample's parts go straight in, times the
// path's throughput there, which the stage sets before direct_light_sampled_lobes
// (light_group_throughput): no second array per group, whose loop at every light sample
// kept the eye stage in local memory (docs/light_groups.md, Cost).
vec3 light_group_eye[LIGHT_GROUPS];
vec3 light_group_throughput = vec3(0.0);
// What light_along_bsdf_sample's terms are multiplied by after it returns (f cos), so that
// it can hand each its group's share (common/light_sampling.glsl).
vec3 light_group_bsdf_weight = vec3(0.0);

void light_groups_begin() {
    for (uint g = 0u; g < uint(LIGHT_GROUPS); ++g) light_group_eye[g] = vec3(0.0);
}

// A part of direct_light_sampled_lobes' result from an emitter of this code.
void light_group_sampled_add(uint code, vec3 part) {
    if (code > 0u) light_group_eye[code - 1u] += light_group_throughput * part;
}

// Light the eye path adds to Combined (eye_trace.comp, ADD_LIGHT): into its emitter's group.
// LIGHT_GROUP_SAMPLED: the light sample's parts, already in (light_group_sampled_add).
void light_group_add(uint code, vec3 light) {
    if (code > 0u && code != LIGHT_GROUP_SAMPLED) light_group_eye[code - 1u] += light;
}

// The sample's light per group into the groups' eye sums. A group this sample did not
// reach is left alone: most samples light one or two groups, and each add reads and
// writes two vec4 (Kahan's sum: not adding a zero only leaves its compensation unfolded).
void store_light_groups(uint pixel) {
    for (uint g = 0u; g < uint(LIGHT_GROUPS); ++g)
        if (any(notEqual(light_group_eye[g], vec3(0.0))))
            pass_add(pixel, light_group_record(g), vec4(light_group_eye[g], 0.0));
}
#endif

#endif
#endif
