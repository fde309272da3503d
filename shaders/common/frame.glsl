// Per-pass constants shared by every stage (std140 uniform block, mirrored by FrameBlock in
// native/render/gpu_layout.h).
#ifndef FRAME_GLSL
#define FRAME_GLSL

layout(std140, binding = 0) uniform Frame {
    mat4 camera_to_world;
    vec4 camera_fov;     // tan(fov_x/2), tan(fov_y/2), shift x and y on the z = -1 plane
    vec4 camera_lens;    // projection (0 perspective, 1 ortho), ortho half width, aperture, focus
    vec4 scene_lo;       // scene bounds: lo.xyz, ray offset scale (scene-relative floor)
    vec4 scene_sphere;   // bounding sphere centre, radius
    vec4 environment;    // constant world radiance (rgb)
    uvec4 sizes;         // image width, height, photon threads, hash cells
    uvec4 pass_info;     // pass index, seed, max depth, emitter count
    vec4 sppm;           // alpha, radius floor, 1 / passes, 1 / photons emitted
    mat4 environment_from_world;  // rotation into the environment map's frame
    ivec4 environment_map;        // texture index, distribution width and height, 0
};

const float PI = 3.14159265358979;

// One thread per item; dispatches may be 2-D when there are more groups than a row holds.
uint thread_index() {
    return gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x;
}

#endif
