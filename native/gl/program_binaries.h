// Linked programs kept as driver binaries for the life of the process, so that a new
// renderer (a new context) of a variant already built skips compiling and linking
// (glGetProgramBinary / glProgramBinary, GL 4.1). Keyed by the driver and the full source,
// so an edited shader or another GPU never picks up a stale binary.
#pragma once

#include <epoxy/gl.h>

#include <cstdint>
#include <string>

namespace glslppm::gl {

struct ProgramBinaryCounts {
    std::uint64_t compiled = 0;  // programs compiled from source
    std::uint64_t reused = 0;    // programs loaded from a kept binary
};

// Loads the binary kept under `key` into `program` (a fresh glCreateProgram); false when
// none is kept or the driver refuses it (then compile as usual).
bool load_program_binary(GLuint program, const std::string& key);
// Keeps the linked `program`'s binary under `key` (link it with
// GL_PROGRAM_BINARY_RETRIEVABLE_HINT set). Does nothing where the driver has no formats.
void keep_program_binary(GLuint program, const std::string& key);
// Counts since the process started (thread-safe).
ProgramBinaryCounts program_binary_counts();
void count_compiled_program();

}  // namespace glslppm::gl
