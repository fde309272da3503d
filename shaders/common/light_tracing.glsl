// Light tracing of L S+ D E paths (HAS_LIGHT_TRACING; issue 28's first step towards VCM): a
// photon whose every scatter so far was smooth (mirror, glass) lands on a diffuse surface
// and is connected to the camera, a caustic seen directly. The gather leaves these photons
// out at visible points seen directly (light_traced in common/light_splats.glsl), so the two
// techniques partition the paths with no MIS: unbiased, not yet the lower variance of VCM's
// weights. Surfaces that only reflect (Lambert; with the rough lobes also plastic, rough metal
// and mixes of these: light_traceable below), pinhole and orthographic cameras only
// (native/render/specializations.cpp).
//
// A pixel j's value is the mean radiance over its area A on the film plane (the box filter
// of the eye's jittered rays). For a photon of flux Phi (one of N_emitted paths) at x, seen
// at distance d along a ray at angle theta_c off the camera's axis, the change from film area
// to surface area, du = cos(theta_x) dA / (d^2 cos^3(theta_c)), gives the splat
//     Phi f(wi, wo) cos(theta_x) / (A d^2 cos^3(theta_c) N_emitted)
// (Veach 1997, section 10.3.3: W_e = 1 / (A cos^4(theta_c)) times G = cos cos / d^2); an
// orthographic film maps areas by du = cos(theta_x) dA alone. A thin lens (depth of field)
// is a pinhole at a point of its disc drawn as the eye path draws it, uniformly: for a fixed
// lens point the film position of x is that pinhole's projection plus a constant, so the same
// splat holds with d and theta_c measured from the lens point (the disc's density cancels
// the eye path's). Include after
// common/surface.glsl, common/bsdf.glsl and common/bounces.glsl.
#ifndef LIGHT_TRACING_GLSL
#define LIGHT_TRACING_GLSL
#define USES_LIGHT_SPLATS
#include "common/light_splats.glsl"

// Whether the camera sees `p` (on a surface of true normal ng) along to_camera, up to
// `distance`: camera rays pass through area-light surfaces and objects hidden from the
// camera (eye_trace.comp), so this ray does too, and stops at anything else. A cut-out (a
// Mix with a Transparent leaf) lets it through where the leaf the eye path would pick there,
// seen from the camera, is the Transparent one: a number drawn per cut-out crossed, so that
// the connection sees through it as often as camera rays do.
bool camera_sees(vec3 p, vec3 ng, vec3 to_camera, float distance, inout RNG_STATE rng) {
    vec3 target = p + to_camera * distance;
    vec3 origin = offset_origin(p, ng, to_camera);
    for (uint k = 0u; k <= max_bounces; ++k) {
        Ray r = make_ray(origin, to_camera);
        r.tmax = dot(target - origin, to_camera);
        Hit hit = closest_hit(r);
        if (hit.triangle < 0) return true;
        Surface s = surface_at(r, hit);
        int flags = material_flags(s.material);
        if ((flags & (MATERIAL_LIGHT_SURFACE | MATERIAL_HIDDEN_FROM_CAMERA)) == 0) {
            if ((flags & MATERIAL_MAY_BE_TRANSPARENT) == 0) return false;
            Shading sh = shading_at(s.material, s.normal, s.geometric_normal, texture_point(s),
                                    s.vertex_color, to_camera, rng_next(rng));
            if (sh.kind != MATERIAL_TRANSPARENT) return false;
        }
        origin = offset_origin(s.position, s.geometric_normal, to_camera);
    }
    return false;
}

#ifdef HAS_ROUGH_LOBES
// Whether every leaf of material m only reflects (Lambert, plastic, metal): a visible point
// seen directly there gathers photons from the camera's side alone, which the connection
// below evaluates as the gather would. Glass and translucent leaves, which gather from both
// sides, and a mix deeper than the stack stay with the gather.
bool material_only_reflects(int m) {
    int stack[16];
    int top = 0;
    stack[top++] = m;
    for (int steps = 0; steps < 64 && top > 0; ++steps) {
        int k = stack[--top];
        int kind = material_kind(k);
        if (kind == MATERIAL_MIX) {
            if (top + 2 > 16) return false;
            ivec2 ab = material_mix(k);
            stack[top++] = ab.x;
            stack[top++] = ab.y;
        } else if (kind != MATERIAL_DIFFUSE && kind != MATERIAL_PLASTIC &&
                   kind != MATERIAL_CONDUCTOR) {
            return false;
        }
    }
    return top == 0;
}
#endif

// Whether light tracing takes the L S+ photons that land on s's material (else they stay the
// gather's, stored as scattered light): a surface that only reflects, whose f the connection
// evaluates as the gather would at a visible point seen directly. Not with normal maps (their
// cosine ratio is not in the connection yet).
bool light_traceable(Surface s) {
#if defined(HAS_NORMAL_MAP)
    return false;
#elif defined(HAS_ROUGH_LOBES)
    return material_only_reflects(s.material);
#else
    return material_kind(s.material) == MATERIAL_DIFFUSE;
#endif
}

// The f a visible point seen directly at s would weigh this photon by: Lambert's albedo / pi,
// or (with the rough lobes) the leaf the eye path would pick at wo = to_camera, by the number
// u_leaf, its lobes the eye path does not follow (none where it follows them all; rough_only
// where it follows smooth ones), within the Light Paths limits of the photon's bounce word.
// Zero where the photon or the camera is below the shading normal.
vec3 connection_f(Surface s, vec3 dir, vec3 to_camera, uint path_bounces, float u_leaf) {
    uint kinds = gather_bounce_kinds(0u, path_bounces);
#ifdef HAS_ROUGH_LOBES
    Shading sh = shading_at(s.material, s.normal, s.geometric_normal, texture_point(s),
                            s.vertex_color, to_camera, u_leaf);
    if (sh.kind == MATERIAL_DIFFUSE) {
        if ((kinds & (1u << BOUNCE_DIFFUSE)) == 0u || dot(-dir, sh.n) <= 0.0) return vec3(0.0);
        return sh.color / PI;
    }
    // A leaf the eye path always follows (a metal below the glossy threshold) never holds a
    // visible point there: nothing to connect.
    float p_smooth = bsdf_smooth_probability(sh, to_camera);
    if (p_smooth >= 1.0) return vec3(0.0);
    return bsdf_f_of_kinds(sh, to_camera, -dir, p_smooth > 0.0, false, kinds);
#else
    if ((kinds & (1u << BOUNCE_DIFFUSE)) == 0u) return vec3(0.0);
    vec3 n = dot(to_camera, s.geometric_normal) > 0.0 ? s.normal : -s.normal;
    if (dot(-dir, n) <= 0.0) return vec3(0.0);
    return surface_color(s) / PI;  // Lambert (light_traceable), as the gather weighs it
#endif
}

// Where the camera sees the point p from its lens point lens_u (a thin lens's, drawn
// uniformly; ignored by other cameras): the pixel, the unit direction and distance to the
// camera, and the importance factor of the splat below (1 / (d^2 cos^3(theta_c)) for a
// perspective camera, 1 for an orthographic one). False behind the camera or off the film.
bool camera_projection(vec3 p, vec2 lens_u, out uint pixel_index, out vec3 to_camera,
                       out float distance, out float importance) {
    pixel_index = 0u;
    to_camera = vec3(0.0, 0.0, 1.0);
    distance = 0.0;
    importance = 0.0;
    // The camera's frame is rigid (scene_features.cpp checks it): its inverse is the
    // transpose, and camera-space distances and angles are the world's.
    vec3 local = transpose(mat3(camera_to_world)) * (p - camera_to_world[3].xyz);
    if (local.z >= 0.0) return false;  // behind the camera (or its film plane)
    vec2 film;
    if (orthographic != 0u) {
        film = local.xy;
        to_camera = normalize(camera_to_world[2].xyz);
        distance = -local.z;
        importance = 1.0;
    } else {
#ifdef HAS_DEPTH_OF_FIELD
        // The lens point, in camera space (z = 0), and where the ray from it through x meets
        // the plane of focus, on the film of camera_ray_at (common/camera.glsl).
        vec3 lens = vec3(aperture_radius * sample_disc(lens_u.x, lens_u.y), 0.0);
        vec3 from_lens = local - lens;
        film = from_lens.xy / -from_lens.z + lens.xy / focus_distance;
        distance = length(from_lens);
        to_camera = -(mat3(camera_to_world) * from_lens) / distance;
        float cos_camera = -from_lens.z / distance;
#else
        film = local.xy / -local.z;
        distance = length(local);
        to_camera = normalize(camera_to_world[3].xyz - p);
        float cos_camera = -local.z / distance;
#endif
        importance = 1.0 / (distance * distance * cos_camera * cos_camera * cos_camera);
    }
    // camera_ray_at (common/camera.glsl) backwards: film -> [-1, 1] -> pixels, row 0 on top.
    vec2 ndc = (film - film_shift) / film_half_extent;
    vec2 pixel = vec2(0.5 * (ndc.x + 1.0) * float(image_width),
                      0.5 * (1.0 - ndc.y) * float(image_height));
    if (!(pixel.x >= 0.0 && pixel.y >= 0.0 && pixel.x < float(image_width) &&
          pixel.y < float(image_height)))
        return false;
    pixel_index = min(uint(pixel.y), image_height - 1u) * image_width +
                  min(uint(pixel.x), image_width - 1u);
    return true;
}

// camera_projection of a light path's point s, arriving along dir, where the camera may see
// it: a surface the camera does not skip, whose true side the path lit faces the camera (the
// gather's side test; connection_f tests the shading normal's side), cos_surface the cosine
// there.
bool camera_connection(Surface s, vec3 dir, vec2 lens_u, out uint pixel_index,
                       out vec3 to_camera, out float distance, out float cos_surface,
                       out float importance) {
    cos_surface = 0.0;
    bool seen = camera_projection(s.position, lens_u, pixel_index, to_camera, distance,
                                  importance);
    if (!seen || (material_flags(s.material) & MATERIAL_HIDDEN_FROM_CAMERA) != 0) return false;
    vec3 lit_side = dot(dir, s.geometric_normal) < 0.0 ? s.geometric_normal : -s.geometric_normal;
    cos_surface = dot(to_camera, lit_side);
    return cos_surface > 0.0;
}

// Splats the photon that just landed at s, arriving along dir with `flux` and the path's
// bounce word, into the pixel the camera sees it in, where the gather would have taken it
// at a visible point seen directly: a surface the camera does not skip, the light and the
// camera on the side of it the photon lit, weighed by connection_f. u_leaf picks a mix's
// leaf, lens_u the point of a thin lens; rng gives the numbers for cut-outs crossed.
void splat_to_camera(Surface s, vec3 dir, vec3 flux, uint path_bounces, float u_leaf,
                     vec2 lens_u, inout RNG_STATE rng) {
    uint i;
    vec3 to_camera;
    float distance, cos_surface, importance;
    if (!camera_connection(s, dir, lens_u, i, to_camera, distance, cos_surface, importance))
        return;
    vec3 f = connection_f(s, dir, to_camera, path_bounces, u_leaf);
    if (f == vec3(0.0)) return;
    if (!camera_sees(s.position, s.geometric_normal, to_camera, distance, rng)) return;
    light_splat_add(i, flux * f * (cos_surface * importance));
#if defined(LIGHT_GROUPS) && defined(USES_PHOTON_PATHS)  // the path's group (emit_photon)
    light_splat_group_add(i, photon_group_code, flux * f * (cos_surface * importance));
#endif
}

#endif
