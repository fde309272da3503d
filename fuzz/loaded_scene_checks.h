// What the loader fuzz targets require of every scene a loader returns: a mesh that
// validate_mesh accepts and materials, lights, camera and world that validate_scene accepts
// (a loader names a bad value in the file; it never hands one on). A violation is a defect: print it and abort, so libFuzzer keeps the
// input.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "loaders/scene_file.h"
#include "scene/mesh.h"
#include "scene/scene_validation.h"

namespace glslppm::fuzz {

[[noreturn]] inline void defect(const char* target, const char* what) {
    std::fprintf(stderr, "%s: %s\n", target, what);
    std::abort();
}

inline void check_loaded_mesh(const LoadedScene& loaded, const char* target) {
    const Scene& s = loaded.scene;
    try {
        validate_mesh(s.mesh, static_cast<std::uint32_t>(s.materials.size()));
    } catch (const SceneError& e) {
        std::fprintf(stderr, "loaded scene fails validation: %s\n", e.what());
        defect(target, "the loader returned a mesh that validate_mesh rejects");
    }
    try {
        validate_scene(s);
    } catch (const SceneError& e) {
        std::fprintf(stderr, "loaded scene fails validation: %s\n", e.what());
        defect(target, "the loader returned a scene that validate_scene rejects");
    }
}

}  // namespace glslppm::fuzz
