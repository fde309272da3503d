// A 64-bit fingerprint of everything a Scene holds that can change its image: farm renders of
// one frame are merged only when their scenes hash alike (render/farm_merge.h). A field added
// to Scene, Material, Light, Camera or Texture belongs in scene_hash.cpp too.
#pragma once

#include <cstdint>
#include <string>

#include "scene/cancel.h"
#include "scene/scene.h"

namespace glslppm {

// Setting `cancel` meanwhile stops it within a MiB of hashing: Cancelled.
std::uint64_t scene_hash(const Scene& scene, const CancelFlag* cancel = nullptr);
std::string scene_hash_hex(const Scene& scene, const CancelFlag* cancel = nullptr);  // 16 hex digits
std::string scene_hash_hex(std::uint64_t hash);
// scene_hash in two parts, so that a renderer that only changes its camera (the viewport's
// set_camera) hashes the camera alone: everything but the camera, then that with a camera.
std::uint64_t scene_hash_without_camera(const Scene& scene, const CancelFlag* cancel = nullptr);
std::uint64_t scene_hash_with_camera(std::uint64_t without_camera, const Camera& camera);

}  // namespace glslppm
