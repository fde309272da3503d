#include "gl/object_counts.h"

#include <atomic>

namespace glslppm::gl {
namespace {

std::atomic<std::int64_t> counts[5];

}  // namespace

void count_gl_objects(GlObject kind, std::int64_t delta) {
    counts[static_cast<int>(kind)] += delta;
}

GlObjectCounts gl_object_counts() {
    return {counts[0].load(), counts[1].load(), counts[2].load(), counts[3].load(),
            counts[4].load()};
}

}  // namespace glslppm::gl
