#include "scene/light_groups.h"

#include <stdexcept>
#include <string>

namespace glslppm {

void assign_light_groups_round_robin(Scene& scene, int groups) {
    if (groups < 1 || groups > MAX_LIGHT_GROUPS)
        throw std::invalid_argument("--light-groups: " + std::to_string(groups) +
                                    " is not between 1 and " + std::to_string(MAX_LIGHT_GROUPS));
    scene.light_groups.clear();
    for (int g = 0; g < groups; ++g) scene.light_groups.push_back("group" + std::to_string(g));
    int next = 0;
    const auto take = [&] {
        const int g = next;
        next = (next + 1) % groups;
        return g;
    };
    for (Material& m : scene.materials)
        if (m.emission.x > 0.0f || m.emission.y > 0.0f || m.emission.z > 0.0f)
            m.light_group = take();
    for (Light& light : scene.lights) light.light_group = take();
    scene.world_light_group = take();
}

}  // namespace glslppm
