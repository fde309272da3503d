// Denoising Albedo and Denoising Normal as Cycles writes them (kernel/film/
// denoising_passes.h, the same in 3.4 and 4.x). At each surface the camera path meets, the
// material's lobes are weighed by their expected albedo (every Mix by its factor: the mean
// over the lobes, not the one this sample picked, so a flat Principled face is noiseless)
// and split into diffuse-like lobes (Lambert, translucent, GGX alpha above 0.075) and
// specular ones. Where the diffuse-like lobes carry more than a quarter of the weight, the
// features are written there: the albedo is the feature throughput times their albedo, the
// normal the shading normal in Cycles' camera space (x right, y up, z along the view).
// Otherwise the feature throughput is multiplied by the specular lobes' albedo (not by what
// the path sampled) and the features wait for the next surface. Emission and the world seen
// on the way add to the albedo, as Cycles' film_write_emission_or_background_pass does.
#ifndef DENOISING_FEATURES_GLSL
#define DENOISING_FEATURES_GLSL

#include "common/bsdf.glsl"
#include "common/lobes.glsl"
#include "common/frame.glsl"

struct SurfaceFeatures {
    vec3 diffuse;          // albedo of the diffuse-like lobes
    vec3 specular;         // albedo of the specular ones
    float diffuse_weight;  // Cycles' sample weights: each lobe's mean albedo
    float weight;
};

// Cycles' bsdf_get_specular_roughness_squared > 0.075^2: GGX alpha above 0.075.
const float DENOISING_SPECULAR_ALPHA = 0.075;

void add_feature_lobe(inout SurfaceFeatures f, vec3 albedo, bool diffuse_like) {
    float w = (albedo.r + albedo.g + albedo.b) / 3.0;
    f.weight += w;
    if (diffuse_like) {
        f.diffuse += albedo;
        f.diffuse_weight += w;
    } else {
        f.specular += albedo;
    }
}

// Glass: Fresnel's share reflected (white, or tinted where the material tints reflection),
// the rest transmitted through the colour (Cycles 4.x's bsdf_microfacet_estimate_albedo).
vec3 dielectric_feature_albedo(float c, float ior, bool entering, vec3 color, vec3 reflection) {
    float cos_t;
    float f = fresnel_dielectric(clamp(c, 0.0, 1.0), entering ? 1.0 / ior : ior, cos_t);
    return f * reflection + (1.0 - f) * color;
}

void add_leaf_features(inout SurfaceFeatures f, Shading sh, vec3 wo_world, float weight) {
    float mu = clamp(dot(wo_world, sh.n), 0.0, 1.0);
    bool rough = sh.alpha > DENOISING_SPECULAR_ALPHA;
    switch (sh.kind) {
        case MATERIAL_DIFFUSE:
        case MATERIAL_TRANSLUCENT: add_feature_lobe(f, weight * sh.color, true); break;
        case MATERIAL_CONDUCTOR:
            add_feature_lobe(f, weight * conductor_fresnel(sh, mu), rough);
            break;
        case MATERIAL_DIELECTRIC: {
            vec3 reflection = (sh.options & OPTION_TINT_REFLECTION) != 0u ? sh.color : vec3(1.0);
            add_feature_lobe(f, weight * dielectric_feature_albedo(mu, sh.ior, sh.entering,
                                                                   sh.color, reflection), rough);
            break;
        }
        case MATERIAL_PLASTIC: {
            // The layer reflects E(mu); the Lambert base under it gets the rest.
            float e = sh.table >= 0 ? plastic_layer_albedo(sh, mu) : 0.0;
            add_feature_lobe(f, vec3(weight * e), rough);
            add_feature_lobe(f, weight * (1.0 - e) * sh.color, true);
            break;
        }
        default: add_feature_lobe(f, weight * sh.color, false); break;  // transparent
    }
}

// The features of material (a triangle's own, mixes and all) seen from wo; n is the
// shading normal on wo's side (Shading's n).
SurfaceFeatures surface_features(int material, vec3 n, TexturePoint at, vec3 vertex_color,
                                 vec3 wo,
                                 bool entering) {
    SurfaceFeatures f = SurfaceFeatures(vec3(0.0), vec3(0.0), 0.0, 0.0);
    float c = clamp(dot(wo, n), 0.0, 1.0);
    // Depth first over the mix tree: each pop leaves at most one sibling per level behind.
    const int STACK = MAX_MIX_DEPTH + 2;
    int stack_m[STACK];
    float stack_w[STACK];
    int depth_of[STACK];
    int top = 1;
    stack_m[0] = material;
    stack_w[0] = 1.0;
    depth_of[0] = 0;
    for (int guard = 0; guard < 64 && top > 0; ++guard) {
        --top;
        int m = stack_m[top];
        float w = stack_w[top];
        int depth = depth_of[top];
        if (material_kind(m) == MATERIAL_MIX && depth < MAX_MIX_DEPTH && top + 2 <= STACK) {
            float k = mix_factor(m, at, c, entering);
            ivec2 ab = material_mix(m);
            stack_m[top] = ab.x;
            stack_w[top] = w * (1.0 - k);
            depth_of[top] = depth + 1;
            stack_m[top + 1] = ab.y;
            stack_w[top + 1] = w * k;
            depth_of[top + 1] = depth + 1;
            top += 2;
        } else if (w > 0.0 && material_kind(m) != MATERIAL_MIX) {
            add_leaf_features(f, shading_of_leaf(m, n, at, vertex_color, entering), wo, w);
        }
    }
    return f;
}

// A world direction in Cycles' camera space: x right, y up, z along the view (the camera
// looks down its local -z in Blender; Cycles' camera matrices carry no scale).
vec3 to_cycles_camera(vec3 d) {
    return vec3(dot(d, normalize(camera_to_world[0].xyz)), dot(d, normalize(camera_to_world[1].xyz)),
                -dot(d, normalize(camera_to_world[2].xyz)));
}

// The camera path's features so far: written once `pending` turns false.
struct DenoisingFeatures {
    vec3 throughput;  // the specular surfaces' albedo in front of the next surface
    vec3 albedo;
    vec3 normal;      // Cycles' camera space
    bool pending;
};

DenoisingFeatures start_denoising_features() {
    return DenoisingFeatures(vec3(1.0), vec3(0.0), vec3(0.0), true);
}

// Light (emission, the world) seen before the features' surface.
void add_feature_light(inout DenoisingFeatures d, vec3 radiance) {
    if (d.pending) d.albedo += d.throughput * radiance;
}

// A surface with features f and shading normal n (on the viewer's side).
void add_feature_surface(inout DenoisingFeatures d, SurfaceFeatures f, vec3 n) {
    if (!d.pending) return;
    if (f.weight == 0.0 || 4.0 * f.diffuse_weight > f.weight) {
        d.albedo += d.throughput * f.diffuse;
        d.normal = f.weight > 0.0 ? to_cycles_camera(n) : vec3(0.0);
        d.pending = false;
    } else {
        d.throughput *= f.specular;
    }
}

#endif
