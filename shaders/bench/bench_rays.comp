// Ray throughput benchmark (glslppm-bench rays): traces one kind of ray per thread through
// common/mtbvh.glsl, MTBVH or TBVH (GLSLPPM_TBVH), and writes one int per ray so that the
// traversal cannot be optimised away. Compiled with exactly one of
//   MODE_PRIMARY     camera rays through a jittered square film, closest hit;
//                    with u_write_hits, also stores each hit for the two modes below;
//   MODE_SHADOW      from each primary hit towards a random point on a light, any hit;
//   MODE_INCOHERENT  from each primary hit in a cosine-distributed direction about the
//                    normal facing the camera (one diffuse bounce), closest hit.
// With u_record_stride > 0 every stride-th ray is written out with its result, and the
// benchmark traces those same rays on the CPU (native/bvh/traverse_cpu.h) to check them.
// With BVH_COUNT_VISITS (an untimed dispatch: counting costs time) each ray's nodes visited
// and triangles tested are written too, for the CPU's TraversalCounts to match exactly.
#include "common/mtbvh.glsl"

layout(local_size_x = 64) in;

layout(std430, binding = 3) readonly buffer Lights { vec4 light_triangles[]; };  // 3 per light
layout(std430, binding = 4) buffer Hits { vec4 hits[]; };         // 2 per ray: (p, valid), (n, 0)
layout(std430, binding = 5) writeonly buffer Results { int results[]; };
layout(std430, binding = 6) writeonly buffer Records { vec4 records[]; };  // 3 per recorded ray
layout(std430, binding = 7) buffer Count { uint valid_hits; };
#ifdef BVH_COUNT_VISITS
layout(std430, binding = 8) writeonly buffer Work { uvec2 work[]; };  // nodes, triangles
#endif

uniform uint u_count;         // rays in this dispatch
uniform uint u_seed;
uniform uint u_film_width;    // square-ish film of u_count pixels
uniform uint u_film_height;
uniform mat4 u_camera_to_world;
uniform float u_tan_half_fov;
uniform uint u_light_count;
uniform uint u_write_hits;
uniform uint u_record_stride;  // 0: record nothing

// PCG-style integer hash (Jarzynski and Olano 2020, "Hash Functions for GPU Rendering").
uint bench_hash(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

float bench_uniform(inout uint state) {
    state = bench_hash(state);
    return float(state >> 8) * (1.0 / 16777216.0);
}

// A new origin pushed off the surface by a distance relative to the position's magnitude
// (as common/surface.glsl's offset_origin does).
vec3 bench_offset(vec3 p, vec3 n) {
    float m = max(max(abs(p.x), abs(p.y)), max(abs(p.z), 1.0));
    return p + (m * 3.0e-6) * n;
}

Ray bench_ray(vec3 origin, vec3 dir, float tmax) {
    Ray r;
    r.origin = origin;
    r.dir = dir;
    r.tmin = 0.0;
    r.tmax = tmax;
    return r;
}

// The traversal work of this invocation's one ray (zero without BVH_COUNT_VISITS).
uvec2 bench_work() {
#ifdef BVH_COUNT_VISITS
    return uvec2(bvh_nodes_visited, bvh_triangles_tested);
#else
    return uvec2(0u);
#endif
}

void bench_record(uint i, Ray r, int result) {
#ifdef BVH_COUNT_VISITS
    work[i] = bench_work();
#endif
    if (u_record_stride == 0u || i % u_record_stride != 0u) return;
    uint k = 3u * (i / u_record_stride);
    uvec2 w = bench_work();
    records[k] = vec4(r.origin, r.tmin);
    records[k + 1u] = vec4(r.dir, r.tmax);
    records[k + 2u] = vec4(intBitsToFloat(result), uintBitsToFloat(w.x), uintBitsToFloat(w.y), 0.0);
}

// Original triangle id of a packed index (-1 stays -1), as the CPU traversal returns it.
int bench_original_id(int packed_index) {
    return packed_index < 0 ? -1 : floatBitsToInt(triangles[3 * packed_index + 1].w);
}

void main() {
    uint i = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u;
    if (i >= u_count) return;
    uint state = bench_hash(i ^ bench_hash(u_seed));
#if defined(MODE_PRIMARY)
    uint px = i % u_film_width, py = i / u_film_width;
    vec2 ndc = vec2((float(px) + bench_uniform(state)) / float(u_film_width),
                    (float(py) + bench_uniform(state)) / float(u_film_height)) * 2.0 - 1.0;
    float aspect = float(u_film_height) / float(u_film_width);
    vec3 d = vec3(ndc.x * u_tan_half_fov, -ndc.y * u_tan_half_fov * aspect, -1.0);
    Ray r = bench_ray(u_camera_to_world[3].xyz, normalize(mat3(u_camera_to_world) * d), 3.0e38);
    Hit h = closest_hit(r);
    int id = bench_original_id(h.triangle);
    results[i] = id;
    bench_record(i, r, id);
    if (u_write_hits != 0u) {
        bool valid = h.triangle >= 0;
        vec3 p = r.origin + h.t * r.dir;
        vec3 n = vec3(0.0, 1.0, 0.0);
        if (valid) {
            vec3 a = triangles[3 * h.triangle].xyz;
            n = normalize(cross(triangles[3 * h.triangle + 1].xyz - a,
                                triangles[3 * h.triangle + 2].xyz - a));
            if (dot(n, r.dir) > 0.0) n = -n;  // the side the camera sees
            atomicAdd(valid_hits, 1u);
        }
        hits[2u * i] = vec4(p, valid ? 1.0 : 0.0);
        hits[2u * i + 1u] = vec4(n, 0.0);
    }
#else
    vec4 hp = hits[2u * i];
    if (hp.w == 0.0) {
        results[i] = -2;
#ifdef BVH_COUNT_VISITS
        work[i] = uvec2(0u);
#endif
        return;
    }
    vec3 n = hits[2u * i + 1u].xyz;
    vec3 origin = bench_offset(hp.xyz, n);
#if defined(MODE_SHADOW)
    // A uniform point on a uniformly chosen light triangle; the ray stops just short of it.
    uint l = min(uint(bench_uniform(state) * float(u_light_count)), u_light_count - 1u);
    float s = sqrt(bench_uniform(state)), t = bench_uniform(state);
    vec3 a = light_triangles[3u * l].xyz, b = light_triangles[3u * l + 1u].xyz,
         c = light_triangles[3u * l + 2u].xyz;
    vec3 target = (1.0 - s) * a + s * (1.0 - t) * b + s * t * c;
    Ray r = bench_ray(origin, target - origin, 0.999);
    int result = any_hit(r) ? 1 : 0;
#else
    // Cosine-weighted direction about n (Malley's method: a uniform disc point lifted).
    float r1 = bench_uniform(state), r2 = bench_uniform(state);
    float radius = sqrt(r1), phi = 6.28318531 * r2;
    vec3 tangent = normalize(abs(n.x) > 0.5 ? cross(n, vec3(0, 1, 0)) : cross(n, vec3(1, 0, 0)));
    vec3 bitangent = cross(n, tangent);
    vec3 dir = radius * cos(phi) * tangent + radius * sin(phi) * bitangent +
               sqrt(max(0.0, 1.0 - r1)) * n;
    Ray r = bench_ray(origin, dir, 3.0e38);
    int result = bench_original_id(closest_hit(r).triangle);
#endif
    results[i] = result;
    bench_record(i, r, result);
#endif
}
