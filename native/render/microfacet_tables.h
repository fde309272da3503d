// Directional albedos of the GGX lobes, integrated on the CPU for the energy compensation of
// shaders/common/lobes.glsl: E(mu, roughness) on a kAlbedoTableSize^2 grid (mu = cos of the
// outgoing direction, Blender's roughness; the grid is uniform in sqrt(mu), which packs nodes
// where the albedo falls at grazing angles, and in roughness, sqrt(mu) fastest), then
// kAlbedoTableSize hemispherical averages E_avg(roughness) = 2 int E(mu) mu dmu of the
// piecewise-linear E the shaders interpolate.
#pragma once

#include <vector>

#include "common/records.glsl"

namespace glslppm {

inline constexpr int kAlbedoTableSize = ALBEDO_TABLE_SIZE;
inline constexpr int kAlbedoTableFloats = kAlbedoTableSize * kAlbedoTableSize + kAlbedoTableSize;

enum class AlbedoLobe {
    WhiteConductor,      // GGX reflection with Fresnel 1
    DielectricOutside,   // rough dielectric, reflection + refraction, light from outside (eta)
    DielectricInside,    // the same from inside (1 / eta)
    DielectricLayer,     // reflection only, with Fresnel of index eta (plastic's layer)
};

// The table of one lobe; `ior` is the dielectric's index (ignored for the conductor).
std::vector<float> albedo_table(AlbedoLobe lobe, float ior);

// GGX with Smith's height-correlated masking, as shaders/common/microfacet.glsl: the single-
// scattering albedo at cos(theta_o) = mu, by the same visible-normal sampling (for tests).
double ggx_albedo(AlbedoLobe lobe, float ior, float mu, float roughness, int strata);

}  // namespace glslppm
