// The instance records of a two-level MTBVH: common/mtbvh.glsl includes this when
// GLSLPPM_INSTANCES is defined, and its one walk (bvh_walk) moves the ray into an instance's
// space and into its tree with these. Mirrors ray_to_instance in native/bvh/traverse_cpu.cpp;
// the buffer layout and the hit rule are documented in native/bvh/two_level_bvh.h.

layout(std430, binding = BINDING_INSTANCES) readonly buffer Instances { vec4 instances[]; };

const int INSTANCE_RECORD_VEC4 = 8;  // kInstanceRecordVec4

// A^-1 (origin - T) and A^-1 dir: t stays the same ray parameter in both spaces.
Ray bvh_ray_to_instance(int instance, Ray world) {
    int base = INSTANCE_RECORD_VEC4 * instance;
    vec4 r0 = instances[base];
    vec4 r1 = instances[base + 1];
    vec4 r2 = instances[base + 2];
    vec3 p = world.origin - vec3(r0.w, r1.w, r2.w);
    Ray r;
    r.origin = vec3(dot(r0.xyz, p), dot(r1.xyz, p), dot(r2.xyz, p));
    r.dir = vec3(dot(r0.xyz, world.dir), dot(r1.xyz, world.dir), dot(r2.xyz, world.dir));
    r.tmin = world.tmin;
    r.tmax = world.tmax;
    return r;
}

// (mesh root node, mesh node count, mesh link base, material offset) of an instance.
ivec4 bvh_instance_bases(int instance) {
    return floatBitsToInt(instances[INSTANCE_RECORD_VEC4 * instance + 6]);
}

#ifdef BVH_ANY_HIT_FILTER
// Defined by the includer: true for a (packed) triangle of an instance that any_hit must not
// count.
bool bvh_any_hit_passes_instanced(int triangle, int instance, float u, float v);
#endif

