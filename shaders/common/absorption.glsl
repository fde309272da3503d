// Homogeneous absorption inside closed objects (Blender's Volume Absorption in a glass,
// glTF's KHR_materials_volume), without any path state: a segment that ends on the BACK
// face of a surface ran inside that object, so it keeps exp(-sigma_a t) of its light
// (Beer-Lambert), t its length and sigma_a the triangle's own material's (a Mix's root).
// Nested or intersecting media and paths that start inside one (a camera or a light in the
// water) are not modelled: they see the medium only where they leave through a back face.
#ifndef ABSORPTION_GLSL
#define ABSORPTION_GLSL

#include "common/scene_buffers.glsl"

// GpuMaterial::absorption (native/render/gpu_layout.h): sigma_a per unit of world length.
vec3 material_absorption(int m) { return material_record(m, MATERIAL_ABSORPTION).xyz; }

// The fraction of light a segment from `origin` to the surface point `p` of material `m`
// keeps: 1 unless it reached the surface from behind (`front` false), inside the object.
// The length is measured in world space, so that instances' scale counts, as in Cycles.
vec3 segment_transmittance(int m, bool front, vec3 origin, vec3 p) {
    if (front) return vec3(1.0);
    return exp(-material_absorption(m) * length(p - origin));
}

#endif
