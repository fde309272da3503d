// Wavefront OBJ with MTL materials into a Scene. Materials map onto the closed model: Kd
// (and map_Kd) diffuse; illum 3/5, or a high-Ns material whose Ks outweighs Kd, a conductor
// of colour Ks; illum 4/6/7 or d < 1 a dielectric of index Ni; Ke emission. Everything else
// is approximated with a warning naming the material. `convention` Glslppm2015 reads the
// MTL as the original glslppm's scene files mean it instead (scene_file.h). A missing .mtl or texture is a
// warning with a fallback; faces of any size are triangulated.
#pragma once

#include <string>

#include "loaders/scene_file.h"

namespace glslppm {

LoadedScene load_obj_file(const std::string& path, float aspect,
                          MtlConvention convention = MtlConvention::Standard);

// `mtl_text` answers every mtllib line; textures are not read (no directory). For the fuzz
// target and tests.
LoadedScene load_obj_from_memory(const std::string& obj_text, const std::string& mtl_text,
                                 const std::string& name, float aspect,
                                 MtlConvention convention = MtlConvention::Standard);

}  // namespace glslppm
