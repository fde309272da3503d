// Per-pass constants shared by every stage: std140, mirrored field by field by FrameBlock in
// native/render/gpu_layout.h (which checks every offset).
#ifndef FRAME_GLSL
#define FRAME_GLSL
#include "common/bindings.glsl"

layout(std140, binding = BINDING_FRAME) uniform Frame {
    mat4 camera_to_world;
    mat4 environment_from_world;  // rotation into the environment map's frame
    // The film's half extent and the centre's shift: on the z = -1 plane (perspective) or
    // in world units (orthographic).
    vec2 film_half_extent;
    vec2 film_shift;
    vec3 scene_lo;                // scene bounds' low corner (the hash grid's origin)
    float ray_offset_floor;       // smallest magnitude ray offsets scale with (scene-relative)
    vec3 scene_center;            // bounding sphere, for distant lights' photons
    float scene_radius;
    vec3 world_radiance;          // constant world radiance (times the map when there is one)
    uint orthographic;            // 1: orthographic camera, 0: perspective
    float aperture_radius;        // thin lens (HAS_DEPTH_OF_FIELD)
    float focus_distance;
    uint image_width;
    uint image_height;
    uint photon_threads;
    uint hash_cell_count;
    uint pass_index;
    uint max_bounces;             // Cycles' Total (common/bounces.glsl)
    uint emitter_count;
    float sppm_alpha;             // SPPM's fraction of new photons kept
    float radius_floor;           // radii never shrink below this (scene-relative)
    float inv_passes;             // 1 / passes run, for the film
    float inv_photons_emitted;    // 1 / photon paths started, for the film
    int environment_texture;      // the map's texture index, -1 for none
    int environment_cdf_width;    // its sampling distribution's size
    int environment_cdf_height;
    float glossy_threshold;       // lobes below this roughness are followed, not gathered
    uint frame_first_pixel;       // the image's first pixel in the whole frame (regions, tiles)
    uint frame_width;             // the whole frame's width
    uint frame_pixels;            // the whole frame's pixel count
    // PPPM (ESTIMATOR_PPPM): this pass's radius r_1 s(i), its estimate's factor
    // 1 / (pi r_i^2 N_emitted), and the photon step within the pass (0 starts every path).
    float pass_radius;
    float pass_scale;
    uint photon_step;
    uint shadow_terminator;       // bump shadowing, 0: Chiang 2019 (Cycles up to 4.x), 1: Conty Estevez 2021 (5.x)
    uint max_diffuse_bounces;     // Cycles' per-kind limits (common/bounces.glsl)
    uint max_glossy_bounces;
    uint max_transmission_bounces;
    float light_splat_unit;       // light tracing's fixed-point unit (common/light_splats.glsl)
    float emitter_mis_fraction;   // q of a Lambertian point's BSDF sample (common/light_sampling.glsl)
    uint render_seed;             // the render's seed folded to 32 bits
    // The light sample's split between the world and the other emitters (light_world_share
    // in common/light_sampling.glsl): centre xyz and spread^2 of the others; their power, the
    // suns' irradiance, the world's irradiance, the world's power-based pick.
    vec4 light_split_centre;
    vec4 light_split_power;
};

const float PI = 3.14159265358979;

// One thread per item; dispatches may be 2-D when there are more groups than a row holds.
uint thread_index() {
    return gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x;
}

#endif
