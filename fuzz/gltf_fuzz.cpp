// libFuzzer target: the glTF loader on .gltf text or .glb bytes (chosen
// by the "glTF" magic), entirely in memory: external buffers and images are never read.
//
// Oracles, each an abort() when it fails:
//   1. The loader returns a scene or throws SceneError (a file it cannot read); any other
//      exception or a crash is a defect.
//   2. A scene it returns passes validate_mesh, and its material and texture references
//      are in range, with every texture's pixel array the size its dimensions say.
// Seeds: tests/fuzz/gltf/.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <span>

#include "loaders/gltf_loader.h"
#include "scene/mesh.h"

#include "loaded_scene_checks.h"

namespace {

using namespace glslppm;

[[noreturn]] void defect(const char* what) { fuzz::defect("gltf_fuzz", what); }

void check(const LoadedScene& loaded) {
    fuzz::check_loaded_mesh(loaded, "gltf_fuzz");
    const Scene& s = loaded.scene;
    for (const Material& m : s.materials)
        if (m.color_texture >= static_cast<std::int32_t>(s.textures.size()))
            defect("a material's texture index is out of range");
    for (const Texture& t : s.textures) {
        const std::size_t texels = std::size_t(t.width) * std::size_t(t.height) * 4;
        if (t.width <= 0 || t.height <= 0 ||
            (t.srgb8.size() != texels) == (t.linear.size() != texels))
            defect("a texture's pixel array does not match its size");
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
    try {
        check(load_gltf_from_memory(std::span(data, size), "fuzz.gltf", 1.5f, binary));
    } catch (const SceneError&) {
        // A file the loader refuses, with a message: the expected outcome for most inputs.
    }
    return 0;
}
