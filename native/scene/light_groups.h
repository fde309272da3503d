// Light groups for scenes that come without them (glslppm-render and glslppm-bench's
// --light-groups N; docs/light_groups.md): every emitter in turn, round robin, into N groups
// named "group0" ... so that a built-in or loaded scene renders N group passes.
#pragma once

#include "scene/scene.h"

namespace glslppm {

// The emissive materials in their order, then the lights, then the world take groups 0, 1,
// ..., N - 1, 0, ... Throws std::invalid_argument unless 1 <= groups <= MAX_LIGHT_GROUPS.
void assign_light_groups_round_robin(Scene& scene, int groups);

}  // namespace glslppm
