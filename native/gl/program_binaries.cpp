#include "gl/program_binaries.h"

#include <mutex>
#include <unordered_map>
#include <vector>

namespace glslppm::gl {
namespace {

struct Binary {
    GLenum format = 0;
    std::vector<std::uint8_t> bytes;
};

struct Store {
    std::mutex mutex;
    std::unordered_map<std::string, Binary> binaries;
    ProgramBinaryCounts counts;
};

Store& store() {
    static Store s;
    return s;
}

}  // namespace

bool load_program_binary(GLuint program, const std::string& key) {
    Binary binary;
    {
        std::lock_guard lock(store().mutex);
        auto it = store().binaries.find(key);
        if (it == store().binaries.end()) return false;
        binary = it->second;
    }
    glProgramBinary(program, binary.format, binary.bytes.data(),
                    static_cast<GLsizei>(binary.bytes.size()));
    GLint ok = GL_FALSE;
    glGetProgramiv(program, GL_LINK_STATUS, &ok);
    while (glGetError() != GL_NO_ERROR) {
    }
    if (ok != GL_TRUE) return false;
    std::lock_guard lock(store().mutex);
    ++store().counts.reused;
    return true;
}

void keep_program_binary(GLuint program, const std::string& key) {
    GLint formats = 0;
    glGetIntegerv(GL_NUM_PROGRAM_BINARY_FORMATS, &formats);
    if (formats <= 0) return;
    GLint length = 0;
    glGetProgramiv(program, GL_PROGRAM_BINARY_LENGTH, &length);
    if (length <= 0) return;
    Binary binary;
    binary.bytes.resize(static_cast<std::size_t>(length));
    GLsizei written = 0;
    glGetProgramBinary(program, length, &written, &binary.format, binary.bytes.data());
    if (glGetError() != GL_NO_ERROR || written <= 0) return;
    binary.bytes.resize(static_cast<std::size_t>(written));
    std::lock_guard lock(store().mutex);
    store().binaries[key] = std::move(binary);
}

ProgramBinaryCounts program_binary_counts() {
    std::lock_guard lock(store().mutex);
    return store().counts;
}

void count_compiled_program() {
    std::lock_guard lock(store().mutex);
    ++store().counts.compiled;
}

}  // namespace glslppm::gl
