// The film, one thread per pixel: L = tau / (pi R^2 N_emitted) + the emission seen
// directly, averaged over the passes (PPPM: the mean of the passes' estimates).
layout(local_size_x = LOCAL_SIZE) in;

#define USES_PIXEL_STATE
#include "common/frame.glsl"
#include "common/bindings.glsl"
#include "common/sppm_buffers.glsl"
#if defined(HAS_LIGHT_TRACING) || defined(VCM_LIGHT_TRACING)
#define USES_LIGHT_SPLATS
#include "common/light_splats.glsl"
#endif

layout(std430, binding = BINDING_FILM) writeonly buffer Film { vec4 film[]; };

void main() {
    uint i = thread_index();
    if (i >= image_width * image_height) return;
    vec3 tau = pixel_stats[2 * i + 0].xyz;
    float r = pixel_stats[2 * i + 1].x;
#if defined(ESTIMATOR_VCM) && !defined(VCM_MERGING)
    // No photons gathered (docs/vcm.md): its paths' light is the direct light's sum.
    vec3 photon_light = vec3(0.0);
#elif defined(ESTIMATOR_PPPM) || defined(ESTIMATOR_VCM)
    // The sum of the passes' own estimates (gather.comp): their mean.
    vec3 photon_light = tau * inv_passes;
#else
    vec3 photon_light = tau * (inv_photons_emitted / (PI * r * r));
#endif
    vec3 direct = direct_light[2 * i + 0].xyz * inv_passes;
#if defined(HAS_LIGHT_TRACING) || defined(VCM_LIGHT_TRACING)
    // Light tracing's splats over every photon path started, as SPPM's tau; PPPM: the mean
    // of its passes' (light_splats.comp).
#if defined(ESTIMATOR_PPPM) || defined(ESTIMATOR_VCM)
    direct += light_splat_sum(i) * (inv_passes / light_splat_pixel_area());
#else
    direct += light_splat_sum(i) * (inv_photons_emitted / light_splat_pixel_area());
#endif
#endif
#ifdef FILM_TRANSPARENT
    float alpha = clamp(1.0 - direct_light[2 * i + 0].w * inv_passes, 0.0, 1.0);
    film[i] = vec4(photon_light + direct, alpha);
#else
    film[i] = vec4(photon_light + direct, 1.0);
#endif
}
