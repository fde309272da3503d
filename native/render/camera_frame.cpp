// The Frame's steps of prepare_scene: the camera's part of the Frame, the automatic radius
// and the Frame's other constants (render/scene_preparation.h). set_camera runs the first
// two again for a new camera.
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "bvh/traverse_cpu.h"
#include "render/camera_ray.h"
#include "render/memory_estimate.h"
#include "render/scene_preparation.h"

namespace glslppm {
WholeFilm camera_frame(const Camera& cam, const RenderSettings& settings, FrameBlock& f) {
    // The whole frame (larger than the image when the image is a render region).
    const bool region = cam.full_width > 0;
    if (region && (cam.region_x + settings.width > cam.full_width ||
                   cam.region_y + settings.height > cam.full_height))
        throw std::invalid_argument(
            "camera region: the image (" + std::to_string(settings.width) + "x" +
            std::to_string(settings.height) + " at " + std::to_string(cam.region_x) + ", " +
            std::to_string(cam.region_y) + ") does not fit in the " +
            std::to_string(cam.full_width) + "x" + std::to_string(cam.full_height) + " frame");
    const int frame_width = region ? cam.full_width : settings.width;
    const int frame_height = region ? cam.full_height : settings.height;
    // The film's height over its width; pixels may be non-square.
    const float aspect =
        static_cast<float>(frame_height) * cam.pixel_aspect / static_cast<float>(frame_width);
    const bool wide =
        static_cast<float>(frame_width) >= static_cast<float>(frame_height) * cam.pixel_aspect;
    const float tan_x = std::tan(0.5f * cam.fov_x);
    const float tan_larger = wide ? tan_x : tan_x * aspect;
    f.camera_to_world = cam.to_world;
    glm::vec2 half_extent, shift;
    if (cam.projection == Projection::Orthographic) {
        // Blender's ortho_scale spans the larger image side.
        const float half_larger = 0.5f * cam.ortho_scale;
        const float half_x = wide ? half_larger : half_larger / aspect;
        half_extent = glm::vec2(half_x, half_x * aspect);
        shift = glm::vec2(2.0f * cam.shift_x * half_larger, 2.0f * cam.shift_y * half_larger);
    } else {
        half_extent = glm::vec2(tan_x, tan_x * aspect);
        shift = glm::vec2(2.0f * cam.shift_x * tan_larger, 2.0f * cam.shift_y * tan_larger);
    }
    // The automatic radius looks through the whole frame, so that a region or a tile of it
    // gathers with the radius the whole frame's render would use.
    const WholeFilm whole{half_extent, shift, frame_width, frame_height};
    if (region) {
        // The window's half extent and centre in the frame's film coordinates ([-1, 1],
        // y up, row 0 at the top).
        const glm::vec2 frame(frame_width, frame_height);
        const glm::vec2 size(settings.width, settings.height);
        const glm::vec2 corner(cam.region_x, cam.region_y);
        const glm::vec2 centre((2.0f * corner.x + size.x) / frame.x - 1.0f,
                               1.0f - (2.0f * corner.y + size.y) / frame.y);
        shift = shift + half_extent * centre;
        half_extent = half_extent * size / frame;
    }
    f.film_half_extent = half_extent;
    f.film_shift = shift;
    f.frame_first_pixel = region ? static_cast<std::uint32_t>(cam.region_y) *
                                           static_cast<std::uint32_t>(frame_width) +
                                       static_cast<std::uint32_t>(cam.region_x)
                                 : 0u;
    f.frame_width = static_cast<std::uint32_t>(frame_width);
    f.frame_pixels =
        static_cast<std::uint32_t>(frame_width) * static_cast<std::uint32_t>(frame_height);
    f.orthographic = cam.projection == Projection::Orthographic ? 1u : 0u;
    f.aperture_radius = cam.aperture_radius;
    f.focus_distance = cam.focus_distance;
    return whole;
}

// Two pixel footprints at the distance of what the camera sees (the median hit distance of
// a 5x5 grid of rays through the film, cast as eye_trace casts its camera rays:
// camera_ray.h), at most 5% of the scene's diagonal.
float automatic_radius(const Camera& cam, const RenderSettings& settings, const FrameBlock& f,
                       const WholeFilm& film, const PackedBvh& bvh, const SceneBounds& bounds,
                       const TwoLevelBvh* two_level) {
    float radius = settings.initial_radius;
    if (radius > 0.0f) return radius;
    const float diagonal = glm::length(bounds.hi - bounds.lo);
    const glm::vec3 eye(cam.to_world[3]);
    // The whole frame seen as a 5 x 5 image, through pixel centres, without the lens.
    FrameBlock whole = f;
    whole.film_half_extent = film.half_extent;
    whole.film_shift = film.shift;
    whole.image_width = whole.image_height = 5;
    std::vector<float> distances;
    for (int j = 0; j < 5; ++j) {
        for (int i = 0; i < 5; ++i) {
            Ray ray = camera_ray_at(whole, glm::vec2(i + 0.5f, j + 0.5f), glm::vec2(0.0f), false);
            ray.dir = glm::normalize(ray.dir);
            if (two_level) {
                const InstanceHit hit = closest_hit(*two_level, ray);
                if (hit.instance >= 0) distances.push_back(hit.t);
            } else {
                const Hit hit = closest_hit(bvh, ray);
                if (hit.triangle >= 0) distances.push_back(hit.t);
            }
        }
    }
    float distance = glm::length(bounds.center() - eye);
    if (!distances.empty()) {
        std::nth_element(distances.begin(), distances.begin() + distances.size() / 2,
                         distances.end());
        distance = distances[distances.size() / 2];
    }
    const float tan_x = std::tan(0.5f * cam.fov_x);
    const float footprint =
        cam.projection == Projection::Orthographic
            ? cam.ortho_scale / static_cast<float>(std::max(film.width, film.height))
            : 2.0f * distance * tan_x / static_cast<float>(film.width);
    radius = std::min(2.0f * footprint, 0.05f * diagonal);
    if (!(radius > 0.0f)) radius = 0.01f * diagonal;
    radius *= settings.radius_scale;
    return radius;
}

float frame_camera(const Camera& cam, const RenderSettings& settings, const PackedBvh& bvh,
                   const SceneBounds& bounds, FrameBlock& f, const TwoLevelBvh* two_level) {
    const WholeFilm film = camera_frame(cam, settings, f);
    return automatic_radius(cam, settings, f, film, bvh, bounds, two_level);
}

// Light tracing's fixed-point unit (shaders/common/light_splats.glsl): a photon of the mean
// flux (the emitters' total power) splatted from the scene's radius onto the axis, as a
// perspective splat's Phi f cos / (d^2 cos^3) reads (Phi f cos alone, orthographic), lands
// at 2^40 units. Splats 2^22 times larger fit in 2^62 and the 64-bit sums still hold 2^30 of
// them a pixel and pass; splats 2^30 times smaller keep 10 bits. Only the precision
// depends on it, never the mean.
static float light_splat_unit(const Camera& camera, glm::vec3 total_power, float scene_radius) {
    double reference = std::max({total_power.x, total_power.y, total_power.z}) / 3.14159265358979;
    if (camera.projection == Projection::Perspective)
        reference /= double(scene_radius) * double(scene_radius);
    const double unit = reference * std::ldexp(1.0, -40);
    if (!(std::isfinite(unit) && unit > 0.0)) return 1.0f;  // no light: nothing splats
    return static_cast<float>(std::clamp(unit, 1e-30, 1e30));
}

void fill_frame(const Scene& scene, const RenderSettings& settings, const PackedBvh& bvh,
                PreparedScene& p) {
    p.pixels =
        static_cast<std::uint32_t>(settings.width) * static_cast<std::uint32_t>(settings.height);
    p.photon_threads = settings.photons_per_pass;
    p.hash_cells = hash_cell_count(p.photon_threads);
    const float diagonal = glm::length(p.bounds.hi - p.bounds.lo);
    FrameBlock& f = p.frame;
    p.initial_radius = frame_camera(scene.camera, settings, bvh, p.bounds, f, p.two_level.get());
    f.scene_lo = p.bounds.lo;
    f.ray_offset_floor = 1e-3f * diagonal;
    f.scene_center = p.bounds.center();
    f.scene_radius = p.bounds.radius();
    f.world_radiance = scene.environment;
    f.environment_from_world = glm::mat4(glm::transpose(scene.environment_to_world));
    if (p.environment) {
        f.environment_texture = scene.environment_texture;
        f.environment_cdf_width = p.environment->width;
        f.environment_cdf_height = p.environment->height;
    }
    f.image_width = static_cast<std::uint32_t>(settings.width);
    f.image_height = static_cast<std::uint32_t>(settings.height);
    f.photon_threads = p.photon_threads;
    f.hash_cell_count = p.hash_cells;
    f.max_bounces = static_cast<std::uint32_t>(settings.max_bounces);
    f.max_diffuse_bounces = static_cast<std::uint32_t>(settings.max_diffuse_bounces);
    f.max_glossy_bounces = static_cast<std::uint32_t>(settings.max_glossy_bounces);
    f.max_transmission_bounces = static_cast<std::uint32_t>(settings.max_transmission_bounces);
    f.glossy_threshold = settings.glossy_threshold;
    // A whole number of 2^-32, as common/light_sampling.glsl's emitter_mis_choice steps by
    // (already so for q >= 2^-8; below, rounded by less than 2^-33).
    f.emitter_mis_fraction = static_cast<float>(
        std::round(static_cast<double>(settings.emitter_mis_fraction) * 4294967296.0) /
        4294967296.0);
    f.render_seed = static_cast<std::uint32_t>(settings.seed ^ (settings.seed >> 32));
    f.shadow_terminator = settings.bump_shadowing == BumpShadowing::Conty2021 ? 1u : 0u;
    f.emitter_count = static_cast<std::uint32_t>(p.emitters.count);
    f.sppm_alpha = settings.alpha;
    f.radius_floor = 1e-5f * diagonal;
    f.light_splat_unit = light_splat_unit(scene.camera, p.emitters.total_power, f.scene_radius);
    const LightSplit split = light_split(p.emitters, f.scene_radius);
    f.light_split_centre = split.centre;
    f.light_split_power = split.power;
}

}  // namespace glslppm
