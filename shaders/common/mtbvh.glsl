// Stackless MTBVH traversal (Hachisuka 2015, "Multiple-Threaded BVH", Figure 3): the ray
// picks one of six hit/miss link sets by its dominant direction component, then follows hit
// links while boxes are hit and miss links otherwise. Mirrors native/bvh/intersect.h and
// native/bvh/traverse_cpu.cpp line by line; the buffer layout is documented in
// native/bvh/packed_bvh.h. Include after "#version 430". Define GLSLPPM_TBVH when the
// buffers hold a single-order threaded BVH (the baseline): every ray then uses order 0.
// Define BVH_COUNT_VISITS (benchmarks and tests only) to count the work of each traversal
// in bvh_nodes_visited and bvh_triangles_tested, exactly where TraversalCounts counts it on
// the CPU: a wrong order choice costs only speed, and these counts are how it shows. Without
// the define BVH_COUNT expands to nothing, so the renderer's code is unchanged. Define
// GLSLPPM_INSTANCES when the buffers hold a two-level MTBVH (common/mtbvh_instances.glsl has
// its instance records; the same walk serves both levels).

#include "common/bindings.glsl"

layout(std430, binding = BINDING_BVH_NODES) readonly buffer BvhNodes { vec4 bvh_nodes[]; };
layout(std430, binding = BINDING_BVH_LINKS) readonly buffer BvhLinks { ivec2 bvh_links[]; };
layout(std430, binding = BINDING_TRIANGLES) readonly buffer Triangles { vec4 triangles[]; };
uniform uint bvh_node_count;

#ifdef BVH_COUNT_VISITS
uint bvh_nodes_visited = 0u;     // slab tests, as TraversalCounts::nodes_visited
uint bvh_triangles_tested = 0u;  // triangle tests, as TraversalCounts::triangles_tested
#define BVH_COUNT(counter) ++counter
#else
#define BVH_COUNT(counter)
#endif

struct Ray {
    vec3 origin;
    vec3 dir;  // need not be normalized; zero components are allowed
    float tmin;
    float tmax;
};

struct Hit {
    float t;
    float u;  // barycentrics of v1 and v2
    float v;
    int triangle;  // PACKED triangle index (fetch triangles[3 * i + k]), -1 for a miss
#ifdef GLSLPPM_INSTANCES
    int instance;  // the instance hit (native/bvh/two_level_bvh.h), -1 for a miss
#endif
};

// kBoxPadRelative and kSlabFarScale of aabb.h / intersect.h.
const float BVH_BOX_PAD_RELATIVE = 1.0 / 524288.0;
const float BVH_SLAB_FAR_SCALE = 1.0 + 1.0 / 16384.0;

// order = 2*axis + (dir[axis] < 0), axis = largest |dir| component, ties to the lower axis.
int bvh_select_order(vec3 d) {
    vec3 a = abs(d);
    int axis = 0;
    if (a.y > a.x) axis = 1;
    if (a.z > a[axis]) axis = 2;
    return 2 * axis + (d[axis] < 0.0 ? 1 : 0);
}

// 1/dir without infinities: zero (or denormal) components become +-1e37, so that slab
// distances are never 0 * inf = NaN.
vec3 bvh_safe_inverse_dir(vec3 d) {
    vec3 tiny = mix(vec3(1e-37), vec3(-1e-37), lessThan(d, vec3(0.0)));
    vec3 c = mix(tiny, d, greaterThan(abs(d), vec3(1e-37)));
    return 1.0 / c;
}

// Slab test of the closed box against [tmin, tmax], inclusive at both ends.
bool bvh_hit_box(vec3 lo, vec3 hi, vec3 origin, vec3 inv_dir, float tmin, float tmax) {
    vec3 t_lo = (lo - origin) * inv_dir;
    vec3 t_hi = (hi - origin) * inv_dir;
    vec3 t_near = min(t_lo, t_hi);
    vec3 t_far = max(t_lo, t_hi);
    float t0 = max(max(t_near.x, t_near.y), max(t_near.z, tmin));
    float t1 = min(min(t_far.x, t_far.y), min(t_far.z, tmax));
    return t0 <= t1 * BVH_SLAB_FAR_SCALE;
}

// Moller-Trumbore with inclusive edges; det == 0 is a miss; t in the open (tmin, tmax).
bool bvh_intersect_triangle(Ray r, vec3 v0, vec3 v1, vec3 v2, out float t, out float u,
                            out float v) {
    t = 0.0;
    u = 0.0;
    v = 0.0;
    vec3 e1 = v1 - v0;
    vec3 e2 = v2 - v0;
    vec3 p = cross(r.dir, e2);
    float det = dot(e1, p);
    if (det == 0.0) return false;
    float inv_det = 1.0 / det;
    vec3 s = r.origin - v0;
    u = dot(s, p) * inv_det;
    if (!(u >= 0.0 && u <= 1.0)) return false;
    vec3 q = cross(s, e1);
    v = dot(r.dir, q) * inv_det;
    if (!(v >= 0.0 && u + v <= 1.0)) return false;
    t = dot(e2, q) * inv_det;
    return t > r.tmin && t < r.tmax;
}

// A Moller-Trumbore hit counts only if [tmin, t] touches the triangle's padded box: keeps
// grazing hits with a wildly wrong t from landing outside the boxes that lead to them.
bool bvh_confirm_triangle_hit(vec3 origin, vec3 inv_dir, float tmin, float t, vec3 v0,
                              vec3 v1, vec3 v2) {
    vec3 lo = min(min(v0, v1), v2);
    vec3 hi = max(max(v0, v1), v2);
    vec3 m = max(abs(lo), abs(hi));
    float pad = max(m.x, max(m.y, m.z)) * BVH_BOX_PAD_RELATIVE;
    return bvh_hit_box(lo - pad, hi + pad, origin, inv_dir, tmin, t);
}

// Smaller t wins; equal t goes to the smaller ORIGINAL triangle id (stored in v1.w).
bool bvh_is_closer(float t, int id, float best_t, int best_id) {
    return t < best_t || (t == best_t && id < best_id);
}

// Where a ray's links of one tree start, so that its (hit, miss) pair of node n is
// bvh_links[link_base + n]: the tree's first link, plus the ray's order times the tree's node
// count (its six link sets lie one after another), less its root (node indices are absolute).
int bvh_tree_link_base(int root, int count, int first_link, vec3 dir) {
#ifdef GLSLPPM_TBVH
    return first_link - root;
#else
    return first_link + bvh_select_order(dir) * count - root;
#endif
}

// Offset of this ray's link set of the tree at node 0 (the only one, or the top one).
int bvh_link_base(vec3 dir) { return bvh_tree_link_base(0, int(bvh_node_count), 0, dir); }

#ifdef GLSLPPM_INSTANCES
#include "common/mtbvh_instances.glsl"
#define BVH_HIT(t, u, v, triangle, instance) Hit(t, u, v, triangle, instance)
#else
#define BVH_HIT(t, u, v, triangle, instance) Hit(t, u, v, triangle)
#endif

// Smaller t wins; equal t goes to the smaller (instance, ORIGINAL triangle id) pair, the order
// of a flattened copy's ids; one level keeps instance -1, leaving the smaller id.
bool bvh_is_closer(float t, int instance, int id, float best_t, int best_instance, int best_id) {
    return t < best_t || (t == best_t && (instance < best_instance ||
                                          (instance == best_instance && id < best_id)));
}

#ifdef BVH_ANY_HIT_FILTER
// Defined by the includer: true for a (packed) triangle that any_hit must not count at the
// hit's barycentrics (u, v), so that shadow rays pass through area-light surfaces as every
// other ray does, and through the transparent parts of cut-outs.
bool bvh_any_hit_passes(int triangle, float u, float v);
#endif

// The one stackless walk of a one-level tree and of both levels of a two-level one
// (GLSLPPM_INSTANCES); traverse_cpu.cpp's walk mirrors it line by line. In a two-level tree
// a top leaf moves the ray into its instance's space and the walk goes on in that
// instance's tree, along the moved ray's own link set; when that tree ends it resumes at the
// top leaf's hit link: the one node index saved across the levels. first_hit: stop at the
// first accepted hit (any_hit). Until a hit is accepted best.t is the ray's tmax and
// bvh_is_closer holds for every triangle hit, so both modes visit the same nodes up to there.
Hit bvh_walk(Ray world, bool first_hit) {
    Hit best = BVH_HIT(world.tmax, 0.0, 0.0, -1, -1);
    int best_instance = -1, best_id = -1;  // of best.triangle, for the tie rule
    if (bvh_node_count == 0u) return best;
    vec3 world_inv_dir = bvh_safe_inverse_dir(world.dir);
    int world_link_base = bvh_link_base(world.dir);
    Ray r = world;
    vec3 inv_dir = world_inv_dir;
    int link_base = world_link_base;
    int instance = -1;  // whose tree the walk is in; -1: the top (or only) tree
    int resume = -1;    // the top node to go on from when the instance's tree ends
    int node = 0;
    while (node != -1) {
        vec4 lo = bvh_nodes[2 * node];
        vec4 hi = bvh_nodes[2 * node + 1];
        BVH_COUNT(bvh_nodes_visited);
        // Inclusive against the best t so far: an equal-t hit may still win on its id (until
        // an any-hit walk accepts one, best.t is the ray's tmax).
        if (bvh_hit_box(lo.xyz, hi.xyz, r.origin, inv_dir, r.tmin, first_hit ? r.tmax : best.t)) {
            int count = floatBitsToInt(hi.w);
            int first = floatBitsToInt(lo.w);
#ifdef GLSLPPM_INSTANCES
            if (instance < 0 && count > 0) {  // a top leaf: lo.w is its instance
                ivec4 tree = bvh_instance_bases(first);
                instance = first;
                resume = bvh_links[link_base + node].x;
                r = bvh_ray_to_instance(instance, world);
                inv_dir = bvh_safe_inverse_dir(r.dir);
                link_base = bvh_tree_link_base(tree.x, tree.y, tree.z, r.dir);
                node = tree.y > 0 ? tree.x : -1;
            } else
#endif
            {
                for (int i = first; i < first + count; ++i) {
                    vec4 a = triangles[3 * i];
                    vec4 b = triangles[3 * i + 1];
                    vec4 c = triangles[3 * i + 2];
                    BVH_COUNT(bvh_triangles_tested);
                    float t, u, v;
                    if (bvh_intersect_triangle(r, a.xyz, b.xyz, c.xyz, t, u, v)) {
                        int id = floatBitsToInt(b.w);
                        if ((first_hit ||
                             bvh_is_closer(t, instance, id, best.t, best_instance, best_id)) &&
                            bvh_confirm_triangle_hit(r.origin, inv_dir, r.tmin, t, a.xyz, b.xyz,
                                                     c.xyz)) {
#ifdef BVH_ANY_HIT_FILTER
#ifdef GLSLPPM_INSTANCES
                            if (first_hit && bvh_any_hit_passes_instanced(i, instance, u, v))
                                continue;
#else
                            if (first_hit && bvh_any_hit_passes(i, u, v)) continue;
#endif
#endif
                            best = BVH_HIT(t, u, v, i, instance);
                            best_instance = instance;
                            best_id = id;
                            if (first_hit) return best;
                        }
                    }
                }
                node = bvh_links[link_base + node].x;
            }
        } else {
            node = bvh_links[link_base + node].y;
        }
#ifdef GLSLPPM_INSTANCES
        if (node == -1 && instance >= 0) {  // the instance's tree is done: back to the top
            instance = -1;
            r = world;
            inv_dir = world_inv_dir;
            link_base = world_link_base;
            node = resume;
        }
#endif
    }
    return best;
}

Hit closest_hit(Ray r) { return bvh_walk(r, false); }

bool any_hit(Ray r) { return bvh_walk(r, true).triangle >= 0; }
