// SPPM stage 4, one thread per pixel: the photons within radius R of the pixel's visible
// point, then the progressive update of Hachisuka and Jensen 2009 (SPPM), eq. 4-7:
//   N' = N + alpha M,   R' = R sqrt(N' / (N + M)),   tau' = (tau + Phi) R'^2 / R^2.
// With stochastic hashing a cell's survivor stands for all `count` photons of its cell:
// E[count * [survivor within R]] is the number of that cell's photons within R, so both M
// and Phi stay unbiased. With ESTIMATOR_PPPM the radius is the pass's and the update is a sum
// of the passes' estimates instead; so with VCM's vertex merging (VCM_MERGING, docs/vcm.md),
// whose photons each weigh by their MIS weight (vcm_merge_weight). Cycles' Light Paths limits
// (common/bounces.glsl) take out of Phi the photons, or the lobes of the point's f, whose
// full path they would break; M still counts every photon within R, so the radii shrink as
// they do without limits.
layout(local_size_x = LOCAL_SIZE) in;

#define USES_PIXEL_STATE
#define USES_PHOTONS
#define USES_HASH
#include "common/frame.glsl"
#include "common/sppm_buffers.glsl"
#include "common/hash_grid.glsl"
#include "common/lobes.glsl"
#include "common/visible_points.glsl"
#include "common/pass_films.glsl"
#include "common/bounces.glsl"
#ifdef HAS_LIGHT_TRACING
#include "common/light_splats.glsl"
#endif
#ifdef VCM_MERGING
#include "common/vcm_merging.glsl"
#endif

shared float group_max_radius[LOCAL_SIZE];

// A photon's share of Phi, and with the light split's passes of its path class's share too
// (common/pass_films.glsl): the classes' sums add up to Phi. With light groups, its
// emitter's group's share (common/light_groups.glsl): the groups' and no group's add up to Phi.
#ifdef PASS_PHOTON_SPLIT
#define ADD_PHOTON_CLASS(p, light) phi_class[photon_class(p)] += light;
#else
#define ADD_PHOTON_CLASS(p, light)
#endif
#ifdef LIGHT_GROUPS
#define ADD_PHOTON_GROUP(p, light) \
    { uint code_ = photon_group_of(p); if (code_ > 0u) phi_group[code_ - 1u] += light; }
#else
#define ADD_PHOTON_GROUP(p, light)
#endif
#if defined(PASS_PHOTON_SPLIT) || defined(LIGHT_GROUPS)
#define ADD_PHOTON(p, value) \
    { vec3 light_ = (value); phi += light_; ADD_PHOTON_CLASS(p, light_) ADD_PHOTON_GROUP(p, light_) }
#else
#define ADD_PHOTON(p, value) phi += (value)
#endif

// VCM's merging (common/vcm_merging.glsl): photon p's light at the visible point (shading sh,
// seen from wo) weighs 1 / (1 + dVC_p p_rev pass_scale) against path tracing, p_rev the
// point's BSDF density towards the photon's light; its incoming direction is stored scaled by
// dVC_p (photon_incoming). Elsewhere the direction is stored as it is and every photon
// weighs 1.
#ifdef VCM_MERGING
#define PHOTON_INCOMING_DIR(p) photon_incoming(p)
#define MERGE_WEIGHT(p) vcm_merge_weight(p, sh, wo)
#else
#define PHOTON_INCOMING_DIR(p) photon_record(p, PHOTON_INCOMING).xyz
#define MERGE_WEIGHT(p) 1.0
#endif

// Whether the gather takes photon p at this visible point: not where light tracing splats
// it (common/light_splats.glsl, light_traced).
#ifdef HAS_LIGHT_TRACING
#define GATHERED(p) !light_traced(p, eye_bounces)
#else
#define GATHERED(p) true
#endif

// Whether photon p, at offset d from the visible point, lit the point's side of its surface
// (photon_side_word). Both normals are the true (geometric) surfaces', on the side lit and
// seen: with a the photon's height above the point's tangent plane and b the point's above
// the photon's, flat or concave surfaces face each other (a, b >= 0: a room's corner, as
// always) and the facets of one convex surface lie below each other's planes (a, b <= 0,
// exactly for any polyhedron, however coarse its tessellation: a sphere's facets too), their
// normals within 60 degrees. Left out: a surface facing away (cos below -0.5, the point's own
// back) and every mixed case, a < 0 < b or b < 0 < a: the far wall of a slab (a letter's
// stroke, a thin wall, whatever its thickness), a lower step, the inside of a closed mesh at
// its edges. With shading normals a tessellated sphere's facets, up to its sagitta inside it,
// needed an exception (normals within 26 degrees kept whatever their offsets), which also
// kept the inside of every slab's far wall: the light inside emissive letters, a furnace up
// to 10^4 times brighter than outside, came through as fireflies (Principled text 1.38x
// Cycles at 128 passes, 1.58x at 2048, now 1.10x; a closed slab 3.04x its emission, now
// exact: tests/python/test_photon_sides.py). A lobe that transmits (both_sides) takes photons
// of either side, as before.
bool photon_on_side(uint p, vec3 d, float r, vec3 side, bool both_sides) {
    if (both_sides) return true;
    vec3 n = photon_side(photon_record(p, PHOTON_FLUX).w);
    float c = dot(n, side);
    float a = dot(d, side), b = -dot(d, n);
    // Slack for the side word's rounding where the normals agree, none across an edge.
    float slack = PHOTON_WALL_TOLERANCE * r * max(c, 0.0);
    return c > -PHOTON_SIDE_MIN_COS &&
           ((a >= -slack && b >= -slack) ||
            (c > PHOTON_SIDE_MIN_COS && a <= slack && b <= slack));
}

#if defined(PASS_PHOTON_SPLIT) || defined(LIGHT_GROUPS)
// One class's (or light group's) photons into its pass, updated as Combined's tau is: PPPM
// adds the pass's estimate, SPPM adds and shrinks with the radius.
void update_photon_pass(uint i, uint offset, vec3 weighted_phi, float shrink) {
#if defined(ESTIMATOR_PPPM) || defined(ESTIMATOR_VCM)
    pass_add(i, offset, vec4(weighted_phi * pass_scale, 0.0));
#else
    uint k = pass_record(i, offset);
    pass_films[k].xyz = (pass_films[k].xyz + weighted_phi) * shrink;
#endif
}
#endif

#ifdef PASS_PHOTON_SPLIT
void update_photon_passes(uint i, vec3 weight, vec3 phi_class[3], float shrink) {
#ifdef PASS_DIRECT_PHOTONS
    update_photon_pass(i, PASS_DIRECT + 2u, weight * phi_class[0], shrink);
#endif
#ifdef PASS_INDIRECT
    update_photon_pass(i, PASS_INDIRECT, weight * phi_class[1], shrink);
#endif
#ifdef PASS_CAUSTICS
    update_photon_pass(i, PASS_CAUSTICS, weight * phi_class[2], shrink);
#endif
}
#endif

#ifdef LIGHT_GROUPS
// Each group's photons into its tau, after its eye pair (common/light_groups.glsl).
void update_light_group_passes(uint i, vec3 weight, vec3 phi_group[LIGHT_GROUPS], float shrink) {
    for (uint g = 0u; g < uint(LIGHT_GROUPS); ++g)
        update_photon_pass(i, LIGHT_GROUP_FIRST + 4u * g + 2u, weight * phi_group[g], shrink);
}
#endif

// f(wo, wi) for the kinds in the mask, as bsdf_f_of_kinds gives it (the same bits: a Lambert
// lobe's colour / pi times bump_shadowing's 1.0, where both wo and wi are on n's side).
vec3 photon_f(Shading sh, bool lambert, vec3 lambert_f, vec3 wo, vec3 wi, bool rough_only,
              uint kinds) {
    if (lambert)
        return (kinds & (1u << BOUNCE_DIFFUSE)) != 0u && dot(wi, sh.n) > 0.0 ? lambert_f : vec3(0.0);
    return bsdf_f_of_kinds(sh, wo, wi, rough_only, false, kinds);
}

// Whether the point's f is Lambert's, colour / pi for every wi on the shading normal's side
// (bump_shadowing varies with wi where a normal map tilts the normal).
bool lambert_point(Shading sh) {
#ifdef HAS_NORMAL_MAP
    return false;
#else
    return sh.kind == MATERIAL_DIFFUSE;
#endif
}

// The photons within r of the visible point at x: their count m and their flux times the
// point's f (phi; by path class too with the light split). `lambert`: lambert_point(sh), for
// which f is bsdf_f_of_kinds' own value without its switch.
void gather_photons(vec3 x0, float r, vec3 side, Shading sh, vec3 wo, bool rough_only,
                    uint eye_bounces, bool lambert, inout float m, inout vec3 phi
#ifdef PASS_PHOTON_SPLIT
                    , inout vec3 phi_class[3]
#endif
#ifdef LIGHT_GROUPS
                    , inout vec3 phi_group[LIGHT_GROUPS]
#endif
) {
    // The side photons must have arrived on (sppm_buffers.glsl, photon_side_word): either
    // side for a lobe that transmits.
    bool both_sides = sh.kind == MATERIAL_TRANSLUCENT || sh.kind == MATERIAL_DIELECTRIC;
    vec3 lambert_f = dot(wo, sh.n) > 0.0 ? sh.color / PI : vec3(0.0);
    float cell_size = hash_cell_size();
    ivec3 center = grid_cell(x0, cell_size);
    float r2 = r * r;
    // Cells are as wide as the largest radius, so a neighbour can hold photons within
    // r only where the point lies within r of the face they share: skip the others
    // (exact; the margin covers rounding in the cell coordinates). Radii that have
    // shrunk below the largest then visit 8 cells or fewer instead of 27.
    vec3 inside = (x0 - scene_lo) / cell_size - vec3(center);
    float reach = r / cell_size * 1.001 + 1e-4;
    ivec3 first = ivec3(mix(vec3(0.0), vec3(-1.0), lessThan(inside, vec3(reach))));
    ivec3 last = ivec3(mix(vec3(0.0), vec3(1.0), greaterThan(inside, vec3(1.0 - reach))));
    for (int dz = first.z; dz <= last.z; ++dz)
    for (int dy = first.y; dy <= last.y; ++dy)
    for (int dx = first.x; dx <= last.x; ++dx) {
        ivec3 cell = center + ivec3(dx, dy, dz);
        uvec4 entry = hash_cells[grid_hash(cell)];
#if defined(HASH_STOCHASTIC)
        if (entry.y == 0u) continue;
        uint p = entry.z;
        vec3 x = photon_record(p, PHOTON_POSITION).xyz;
        vec3 d = x - x0;
        // Only from the cell it belongs to: cells sharing a table entry must not
        // count their survivor twice.
        if (dot(d, d) <= r2 && grid_cell(x, cell_size) == cell &&
            photon_on_side(p, d, r, side, both_sides)) {
            vec3 f = photon_f(sh, lambert, lambert_f, wo, PHOTON_INCOMING_DIR(p), rough_only,
                              gather_bounce_kinds(eye_bounces, photon_bounces(p)));
            float count = float(entry.y);
            m += count;
            if (GATHERED(p))
                ADD_PHOTON(p, count * MERGE_WEIGHT(p) * f * photon_record(p, PHOTON_FLUX).xyz);
        }
#else
        for (uint k = entry.y; k < entry.y + entry.x; ++k) {
            uint p = hash_sorted[k];
            vec3 x = photon_record(p, PHOTON_POSITION).xyz;
            vec3 d = x - x0;
            if (dot(d, d) <= r2 && grid_cell(x, cell_size) == cell &&
                photon_on_side(p, d, r, side, both_sides)) {
                m += 1.0;
                if (GATHERED(p))
                    ADD_PHOTON(p, photon_f(sh, lambert, lambert_f, wo, PHOTON_INCOMING_DIR(p),
                                           rough_only,
                                           gather_bounce_kinds(eye_bounces,
                                                               photon_bounces(p))) *
                                      (MERGE_WEIGHT(p) * photon_record(p, PHOTON_FLUX).xyz));
            }
        }
#endif
    }
}

void main() {
    uint i = thread_index();
    float radius_after = 0.0;
    if (i < image_width * image_height) {
        vec4 stats0 = pixel_stats[2 * i + 0];
#if defined(ESTIMATOR_PPPM) || defined(ESTIMATOR_VCM)
        float r = pass_radius;
#else
        float r = pixel_stats[2 * i + 1].x;
#endif
        radius_after = r;
        vec4 point = visible_point_position(i);
        if (point.w >= 0.0) {
            // The visible point's material, to weigh each photon by f(wo, wi).
            VisiblePoint vp = load_visible_point(i);
            uint eye_bounces = vp.bounces;
            Shading sh = shading_of_leaf(int(point.w), vp.normal, TexturePoint(vp.uv, point.xyz),
                                         vp.vertex_color, (vp.flags & VISIBLE_POINT_ENTERING) != 0u);
            bool rough_only = (vp.flags & VISIBLE_POINT_ROUGH_ONLY) != 0u;
            // The true surface's normal on the point's side (eye_trace.comp).
            vec3 side = unpack_octahedral(vp.flags >> VISIBLE_POINT_NORMAL_SHIFT);
#ifdef HAS_NORMAL_MAP
            sh.ng = side;
#endif
            vec3 wo = vp.wo;
            vec3 weight = vp.weight;
            float m = 0.0;
            vec3 phi = vec3(0.0);
#ifdef PASS_PHOTON_SPLIT
            vec3 phi_class[3] = vec3[3](vec3(0.0), vec3(0.0), vec3(0.0));
#define PHOTON_SPLIT_CLASSES , phi_class
#else
#define PHOTON_SPLIT_CLASSES
#endif
#ifdef LIGHT_GROUPS
            vec3 phi_group[LIGHT_GROUPS];
            for (uint g = 0u; g < uint(LIGHT_GROUPS); ++g) phi_group[g] = vec3(0.0);
#define PHOTON_CLASSES PHOTON_SPLIT_CLASSES, phi_group
#else
#define PHOTON_CLASSES PHOTON_SPLIT_CLASSES
#endif
            // A Lambert point's f is one colour on its side: its loop evaluates nothing else.
            // (Called with a constant, each call compiles to its own loop; a loop whose lanes
            // are all idle ends at once, where a branch inside one loop would run every
            // lobe's code masked on llvmpipe: 3.6x the gather's time on the Cornell box.)
            if (lambert_point(sh))
                gather_photons(point.xyz, r, side, sh, wo, rough_only, eye_bounces, true, m, phi
                               PHOTON_CLASSES);
            else
                gather_photons(point.xyz, r, side, sh, wo, rough_only, eye_bounces, false, m, phi
                               PHOTON_CLASSES);
#if defined(ESTIMATOR_PPPM) || defined(ESTIMATOR_VCM)
            // PPPM (Knaus and Zwicker 2011, eq. 9): this step's share of the pass's own
            // estimate weight Phi / (pi r_i^2 N_emitted), summed over steps and passes with
            // Kahan compensation (the compensation in the radius record's spare words).
            if (m > 0.0) {
                vec4 stats1 = pixel_stats[2 * i + 1];
                precise vec3 y = weight * phi * pass_scale - stats1.yzw;
                precise vec3 t = stats0.xyz + y;
                stats1.yzw = (t - stats0.xyz) - y;
                pixel_stats[2 * i + 0] = vec4(t, stats0.w + m);
                pixel_stats[2 * i + 1] = stats1;
#ifdef PASS_PHOTON_SPLIT
                update_photon_passes(i, weight, phi_class, 1.0);
#endif
#ifdef LIGHT_GROUPS
                update_light_group_passes(i, weight, phi_group, 1.0);
#endif
            }
#else
            if (m > 0.0) {
                float n_old = stats0.w;
                float n_new = n_old + sppm_alpha * m;
                // Shrinks to the floor, never grows (a radius already below the floor stays).
                float r_new = max(r * sqrt(n_new / (n_old + m)), min(r, radius_floor));
                float shrink = (r_new * r_new) / (r * r);
                vec3 tau = (stats0.xyz + weight * phi) * shrink;
                pixel_stats[2 * i + 0] = vec4(tau, n_new);
                pixel_stats[2 * i + 1].x = r_new;
                radius_after = r_new;
#ifdef PASS_PHOTON_SPLIT
                update_photon_passes(i, weight, phi_class, shrink);
#endif
#ifdef LIGHT_GROUPS
                update_light_group_passes(i, weight, phi_group, shrink);
#endif
            }
#endif
        }
    }
    // The next pass's cells must hold the largest radius of any pixel: reduce in the work
    // group, then one atomic per group (positive floats order like their bits).
    uint t = gl_LocalInvocationID.x;
    group_max_radius[t] = radius_after;
    barrier();
    for (uint s = LOCAL_SIZE / 2u; s > 0u; s >>= 1u) {
        if (t < s) group_max_radius[t] = max(group_max_radius[t], group_max_radius[t + s]);
        barrier();
    }
    if (t == 0u) atomicMax(max_radius_bits, floatBitsToUint(group_max_radius[0]));
}
