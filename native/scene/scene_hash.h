// A 64-bit fingerprint of everything a Scene holds that can change its image: farm renders of
// one frame are merged only when their scenes hash alike (render/farm_merge.h). A field added
// to Scene, Material, Light, Camera or Texture belongs in scene_hash.cpp too.
#pragma once

#include <cstdint>
#include <string>

#include "scene/scene.h"

namespace glslppm {

std::uint64_t scene_hash(const Scene& scene);
std::string scene_hash_hex(const Scene& scene);  // 16 lower-case hex digits

}  // namespace glslppm
