// Live GL objects and EGL contexts that glslppm created and has not yet deleted, counted
// process-wide where they are created and deleted, so that tests can check that renderers
// leave nothing behind (100 create/destroy cycles must end where they began).
#pragma once

#include <cstdint>

namespace glslppm::gl {

enum class GlObject { Context = 0, Buffer = 1, Texture = 2, Program = 3, Query = 4 };

struct GlObjectCounts {
    std::int64_t contexts = 0, buffers = 0, textures = 0, programs = 0, queries = 0;
};

void count_gl_objects(GlObject kind, std::int64_t delta);
GlObjectCounts gl_object_counts();

}  // namespace glslppm::gl
