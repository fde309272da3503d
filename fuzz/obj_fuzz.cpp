// libFuzzer target: the OBJ/MTL loader, in memory. The input is the .obj
// text, then optionally a NUL byte and the .mtl text that answers every mtllib line.
//
// Oracles, each an abort() when it fails:
//   1. The loader returns a scene or throws SceneError; any other exception or a crash is
//      a defect.
//   2. A scene it returns passes validate_mesh, and every material's texture index is in
//      range (textures are never read in memory mode, so there are none).
// Seeds: tests/fuzz/obj/.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "loaders/obj_loader.h"
#include "scene/mesh.h"

#include "loaded_scene_checks.h"

namespace {

using namespace glslppm;

[[noreturn]] void defect(const char* what) { fuzz::defect("obj_fuzz", what); }

void check(const LoadedScene& loaded) {
    fuzz::check_loaded_mesh(loaded, "obj_fuzz");
    const Scene& s = loaded.scene;
    if (!s.textures.empty()) defect("a texture was read in memory mode");
    for (const Material& m : s.materials)
        if (m.color_texture != -1) defect("a material refers to a texture");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string bytes(reinterpret_cast<const char*>(data), size);
    const std::size_t split = bytes.find('\0');
    const std::string obj = bytes.substr(0, split);
    const std::string mtl = split == std::string::npos ? "" : bytes.substr(split + 1);
    try {
        check(load_obj_from_memory(obj, mtl, "fuzz.obj", 1.5f));
    } catch (const SceneError&) {
        // A file the loader refuses, with a message.
    }
    return 0;
}
