// The built-in scene, like the paper's default: a Cornell box with diffuse coloured walls,
// a mirror sphere, a glass sphere and a ceiling area light. Y is up; the box spans
// x, z in [-1, 1] and y in [0, 2]; the camera looks down -Z from z = 4.
#pragma once

#include "scene/scene.h"

namespace glslppm {

struct CornellBoxOptions {
    bool mirror_sphere = true;
    bool glass_sphere = true;
    int sphere_rings = 48;  // tessellation of each sphere (rings; segments = 2 * rings)
    float light_radiance = 17.0f;
    // The glossy variant (glslppm-bench --scene cornell-glossy): a rough gold sphere
    // (roughness 0.3) for the mirror, frosted glass (0.25) for the glass, and a rough plastic
    // floor (0.4) under them.
    bool glossy = false;
};

Scene make_cornell_box(const CornellBoxOptions& options = {});

}  // namespace glslppm
