// Light tracing of L S+ D E paths (HAS_LIGHT_TRACING; issue 28's first step towards VCM): a
// photon whose every scatter so far was smooth (mirror, glass) lands on a diffuse surface
// and is connected to the camera, a caustic seen directly. The gather leaves these photons
// out at visible points seen directly (light_traced in common/light_splats.glsl), so the two
// techniques partition the paths with no MIS: unbiased, not yet the lower variance of VCM's
// weights. Lambert surfaces, pinhole and orthographic cameras only (light_traceable below,
// native/render/scene_features.cpp).
//
// A pixel j's value is the mean radiance over its area A on the film plane (the box filter
// of the eye's jittered rays). For a photon of flux Phi (one of N_emitted paths) at x, seen
// at distance d along a ray at angle theta_c off the camera's axis, the change from film area
// to surface area, du = cos(theta_x) dA / (d^2 cos^3(theta_c)), gives the splat
//     Phi f(wi, wo) cos(theta_x) / (A d^2 cos^3(theta_c) N_emitted)
// (Veach 1997, section 10.3.3: W_e = 1 / (A cos^4(theta_c)) times G = cos cos / d^2); an
// orthographic film maps areas by du = cos(theta_x) dA alone. Include after
// common/surface.glsl, common/bsdf.glsl and common/bounces.glsl.
#ifndef LIGHT_TRACING_GLSL
#define LIGHT_TRACING_GLSL
#define USES_LIGHT_SPLATS
#include "common/light_splats.glsl"

// Whether the camera sees `p` (on a surface of true normal ng) along to_camera, up to
// `distance`: camera rays pass through area-light surfaces and objects hidden from the
// camera (eye_trace.comp), so this ray does too, and stops at anything else.
bool camera_sees(vec3 p, vec3 ng, vec3 to_camera, float distance) {
    vec3 target = p + to_camera * distance;
    vec3 origin = offset_origin(p, ng, to_camera);
    for (uint k = 0u; k <= max_bounces; ++k) {
        Ray r = make_ray(origin, to_camera);
        r.tmax = dot(target - origin, to_camera);
        Hit hit = closest_hit(r);
        if (hit.triangle < 0) return true;
        Surface s = surface_at(r, hit);
        if ((material_flags(s.material) & (MATERIAL_LIGHT_SURFACE | MATERIAL_HIDDEN_FROM_CAMERA)) ==
            0)
            return false;
        origin = offset_origin(s.position, s.geometric_normal, to_camera);
    }
    return false;
}

// Whether light tracing takes the L S+ photons that land on s's material (else they stay the
// gather's, stored as scattered light): a Lambert surface, whose f the connection evaluates
// as the gather would, albedo / pi. With the lobes, a single diffuse leaf (no mix, plastic or
// translucent yet) and no normal maps (their cosine ratio is not in the connection yet).
bool light_traceable(Surface s) {
#ifdef HAS_NORMAL_MAP
    return false;
#else
    return material_kind(s.material) == MATERIAL_DIFFUSE;
#endif
}

// Splats the photon that just landed at s, arriving along dir with `flux` and the path's
// bounce word, into the pixel the camera sees it in, where the gather would have taken it
// at a visible point seen directly: a diffuse surface the camera does not skip, the light
// and the camera on the side of it the photon lit, within the Light Paths limits.
void splat_to_camera(Surface s, vec3 dir, vec3 flux, uint path_bounces) {
    if ((material_flags(s.material) & MATERIAL_HIDDEN_FROM_CAMERA) != 0) return;
    if ((gather_bounce_kinds(0u, path_bounces) & (1u << BOUNCE_DIFFUSE)) == 0u) return;
    // The camera's frame is rigid (scene_features.cpp checks it): its inverse is the
    // transpose, and camera-space distances and angles are the world's.
    vec3 local = transpose(mat3(camera_to_world)) * (s.position - camera_to_world[3].xyz);
    if (local.z >= 0.0) return;  // behind the camera (or its film plane)
    vec2 film;
    vec3 to_camera;
    float distance, importance;
    if (orthographic != 0u) {
        film = local.xy;
        to_camera = normalize(camera_to_world[2].xyz);
        distance = -local.z;
        importance = 1.0;
    } else {
        film = local.xy / -local.z;
        distance = length(local);
        to_camera = normalize(camera_to_world[3].xyz - s.position);
        float cos_camera = -local.z / distance;
        importance = 1.0 / (distance * distance * cos_camera * cos_camera * cos_camera);
    }
    // camera_ray_at (common/camera.glsl) backwards: film -> [-1, 1] -> pixels, row 0 on top.
    vec2 ndc = (film - film_shift) / film_half_extent;
    vec2 pixel = vec2(0.5 * (ndc.x + 1.0) * float(image_width),
                      0.5 * (1.0 - ndc.y) * float(image_height));
    if (!(pixel.x >= 0.0 && pixel.y >= 0.0 && pixel.x < float(image_width) &&
          pixel.y < float(image_height)))
        return;
    // The true surface's side the photon lit must face the camera (the gather's side test),
    // and the light must arrive above the shading normal facing the camera (its cosine test).
    vec3 lit_side = dot(dir, s.geometric_normal) < 0.0 ? s.geometric_normal : -s.geometric_normal;
    float cos_surface = dot(to_camera, lit_side);
    if (cos_surface <= 0.0) return;
    vec3 n = dot(to_camera, s.geometric_normal) > 0.0 ? s.normal : -s.normal;
    if (dot(-dir, n) <= 0.0) return;
    if (!camera_sees(s.position, s.geometric_normal, to_camera, distance)) return;
    uint i = min(uint(pixel.y), image_height - 1u) * image_width +
             min(uint(pixel.x), image_width - 1u);
    vec3 f = surface_color(s) / PI;  // Lambert (light_traceable), as the gather weighs it
    light_splat_add(i, flux * f * (cos_surface * importance));
}

#endif
