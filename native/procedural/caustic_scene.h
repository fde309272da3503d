// A caustic benchmark scene: a glass sphere (smooth dielectric, ior 1.5) on a white diffuse
// floor in front of a back wall, lit by a small emissive quad off to the side, so that the
// sphere focuses the light into a bright spot on the floor beside it where the camera sees
// it. Y is up; the floor is y = 0.
#pragma once

#include "scene/scene.h"

namespace glslppm {

struct CausticSceneOptions {
    int sphere_rings = 64;          // tessellation of the glass sphere (segments = 2 * rings)
    float light_radiance = 600.0f;  // of the small quad light, W / (m^2 sr)
    float ior = 1.5f;
};

Scene make_caustic_scene(const CausticSceneOptions& options = {});

}  // namespace glslppm
