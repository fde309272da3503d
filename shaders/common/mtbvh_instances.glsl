// Two-level MTBVH traversal for instanced scenes: common/mtbvh.glsl includes this in place of
// its single-level closest_hit and any_hit when GLSLPPM_INSTANCES is defined. The top tree
// (over the instances' world boxes) is walked along the world ray's link set; a top leaf
// moves the ray into its instance's space and walks that mesh's tree along the moved ray's
// own link set; then the top walk goes on from the leaf's link: that node index is the only
// state kept across the two levels. Mirrors native/bvh/two_level_bvh.cpp line by line; the
// buffer layout and the hit rule are documented in native/bvh/two_level_bvh.h.

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

// Smaller t wins; equal t goes to the smaller (instance, original triangle id) pair: the
// order of the flattened copy's ids.
bool bvh_is_closer_instanced(float t, int instance, int id, Hit best, int best_id) {
    return t < best.t ||
           (t == best.t && (instance < best.instance ||
                            (instance == best.instance && id < best_id)));
}

// (mesh root node, mesh node count, mesh link base, material offset) of an instance.
ivec4 bvh_instance_bases(int instance) {
    return floatBitsToInt(instances[INSTANCE_RECORD_VEC4 * instance + 6]);
}

void bvh_walk_instance(int instance, Ray world, inout Hit best, inout int best_id) {
    Ray r = bvh_ray_to_instance(instance, world);
    ivec4 bases = bvh_instance_bases(instance);
    int link_base = bases.z + bvh_select_order(r.dir) * bases.y - bases.x;
    vec3 inv_dir = bvh_safe_inverse_dir(r.dir);
    int node = bases.y > 0 ? bases.x : -1;
    while (node != -1) {
        vec4 lo = bvh_nodes[2 * node];
        vec4 hi = bvh_nodes[2 * node + 1];
        BVH_COUNT(bvh_nodes_visited);
        if (bvh_hit_box(lo.xyz, hi.xyz, r.origin, inv_dir, r.tmin, best.t)) {
            int count = floatBitsToInt(hi.w);
            int first = floatBitsToInt(lo.w);
            for (int i = first; i < first + count; ++i) {
                vec4 a = triangles[3 * i];
                vec4 b = triangles[3 * i + 1];
                vec4 c = triangles[3 * i + 2];
                BVH_COUNT(bvh_triangles_tested);
                float t, u, v;
                if (bvh_intersect_triangle(r, a.xyz, b.xyz, c.xyz, t, u, v)) {
                    int id = floatBitsToInt(b.w);
                    if (bvh_is_closer_instanced(t, instance, id, best, best_id) &&
                        bvh_confirm_triangle_hit(r.origin, inv_dir, r.tmin, t, a.xyz, b.xyz,
                                                 c.xyz)) {
                        best = Hit(t, u, v, i, instance);
                        best_id = id;
                    }
                }
            }
            node = bvh_links[link_base + node].x;
        } else {
            node = bvh_links[link_base + node].y;
        }
    }
}

Hit closest_hit(Ray r) {
    Hit best = Hit(r.tmax, 0.0, 0.0, -1, -1);
    int best_id = -1;  // original id of best.triangle, for the tie rule
    if (bvh_node_count == 0u) return best;
    vec3 inv_dir = bvh_safe_inverse_dir(r.dir);
    int link_base = bvh_select_order(r.dir) * int(bvh_node_count);
    int node = 0;
    while (node != -1) {
        vec4 lo = bvh_nodes[2 * node];
        vec4 hi = bvh_nodes[2 * node + 1];
        BVH_COUNT(bvh_nodes_visited);
        if (bvh_hit_box(lo.xyz, hi.xyz, r.origin, inv_dir, r.tmin, best.t)) {
            if (floatBitsToInt(hi.w) > 0) bvh_walk_instance(floatBitsToInt(lo.w), r, best, best_id);
            node = bvh_links[link_base + node].x;
        } else {
            node = bvh_links[link_base + node].y;
        }
    }
    return best;
}

#ifdef BVH_ANY_HIT_FILTER
// Defined by the includer: true for a (packed) triangle of an instance that any_hit must not
// count.
bool bvh_any_hit_passes_instanced(int triangle, int instance, float u, float v);
#endif

bool bvh_walk_instance_any(int instance, Ray world) {
    Ray r = bvh_ray_to_instance(instance, world);
    ivec4 bases = bvh_instance_bases(instance);
    int link_base = bases.z + bvh_select_order(r.dir) * bases.y - bases.x;
    vec3 inv_dir = bvh_safe_inverse_dir(r.dir);
    int node = bases.y > 0 ? bases.x : -1;
    while (node != -1) {
        vec4 lo = bvh_nodes[2 * node];
        vec4 hi = bvh_nodes[2 * node + 1];
        BVH_COUNT(bvh_nodes_visited);
        if (bvh_hit_box(lo.xyz, hi.xyz, r.origin, inv_dir, r.tmin, r.tmax)) {
            int count = floatBitsToInt(hi.w);
            int first = floatBitsToInt(lo.w);
            for (int i = first; i < first + count; ++i) {
                BVH_COUNT(bvh_triangles_tested);
                vec3 a = triangles[3 * i].xyz;
                vec3 b = triangles[3 * i + 1].xyz;
                vec3 c = triangles[3 * i + 2].xyz;
                float t, u, v;
                if (bvh_intersect_triangle(r, a, b, c, t, u, v) &&
                    bvh_confirm_triangle_hit(r.origin, inv_dir, r.tmin, t, a, b, c)) {
#ifdef BVH_ANY_HIT_FILTER
                    if (bvh_any_hit_passes_instanced(i, instance, u, v)) continue;
#endif
                    return true;
                }
            }
            node = bvh_links[link_base + node].x;
        } else {
            node = bvh_links[link_base + node].y;
        }
    }
    return false;
}

bool any_hit(Ray r) {
    if (bvh_node_count == 0u) return false;
    vec3 inv_dir = bvh_safe_inverse_dir(r.dir);
    int link_base = bvh_select_order(r.dir) * int(bvh_node_count);
    int node = 0;
    while (node != -1) {
        vec4 lo = bvh_nodes[2 * node];
        vec4 hi = bvh_nodes[2 * node + 1];
        BVH_COUNT(bvh_nodes_visited);
        if (bvh_hit_box(lo.xyz, hi.xyz, r.origin, inv_dir, r.tmin, r.tmax)) {
            if (floatBitsToInt(hi.w) > 0 && bvh_walk_instance_any(floatBitsToInt(lo.w), r))
                return true;
            node = bvh_links[link_base + node].x;
        } else {
            node = bvh_links[link_base + node].y;
        }
    }
    return false;
}
