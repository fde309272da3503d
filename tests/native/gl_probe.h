// What the tests that run a small test program of shaders/tests/ on the driver share: one GL
// thread for the whole test binary, storage buffers uploaded and bound by binding point, a
// dispatch of one invocation per item (local size 64), and a buffer read back.
#pragma once

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <initializer_list>
#include <vector>

#include "bvh/intersect.h"
#include "gl/gl_thread.h"

namespace glslppm::gl_probe {

// Every probe of a test binary runs on this thread, so programs are compiled once.
inline gl::GlThread& gl_thread() {
    static gl::GlThread thread;
    return thread;
}

// A storage buffer: its binding point, its contents (null: undefined, for outputs) and size.
struct Buffer {
    GLuint binding;
    const void* data;
    std::size_t bytes;
};

// The buffers of one dispatch, created, filled and bound together; deleted at the end of the
// scope, where glGetError must be clean. Call on the GL thread.
class Buffers {
  public:
    Buffers(std::initializer_list<Buffer> buffers) : sizes_(buffers.size()) {
        names_.resize(buffers.size());
        glGenBuffers(static_cast<GLsizei>(names_.size()), names_.data());
        std::size_t i = 0;
        for (const Buffer& b : buffers) {
            // Never empty: a zero-sized storage buffer cannot be bound.
            sizes_[i] = std::max<std::size_t>(b.bytes, 16);
            glBindBuffer(GL_SHADER_STORAGE_BUFFER, names_[i]);
            glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(sizes_[i]),
                         b.bytes ? b.data : nullptr, GL_DYNAMIC_COPY);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, b.binding, names_[i]);
            ++i;
        }
    }
    ~Buffers() {
        glDeleteBuffers(static_cast<GLsizei>(names_.size()), names_.data());
        EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
    }
    Buffers(const Buffers&) = delete;
    Buffers& operator=(const Buffers&) = delete;

    // The first `count` records of buffer `index` (in the order given to the constructor).
    template <class T>
    std::vector<T> read(std::size_t index, std::size_t count) const {
        std::vector<T> out(count);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, names_[index]);
        glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0,
                           static_cast<GLsizeiptr>(std::min(count * sizeof(T), sizes_[index])),
                           out.data());
        return out;
    }
    // Into memory of the caller's.
    void read_into(std::size_t index, void* out, std::size_t bytes) const {
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, names_[index]);
        glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(bytes), out);
    }

  private:
    std::vector<GLuint> names_;
    std::vector<std::size_t> sizes_;
};

// One invocation per item in groups of 64 (rows of at most 65535 groups), then the barrier
// that makes the results readable.
inline void dispatch_items(std::size_t count) {
    const auto groups = static_cast<GLuint>((count + 63) / 64);
    glDispatchCompute(std::min(groups, 65535u), (groups + 65534) / 65535, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
}

// Rays as the probes read them: (origin, tmin), (dir, tmax).
inline std::vector<glm::vec4> pack_rays(const std::vector<Ray>& rays) {
    std::vector<glm::vec4> packed;
    packed.reserve(2 * rays.size());
    for (const Ray& r : rays) {
        packed.emplace_back(r.origin, r.tmin);
        packed.emplace_back(r.dir, r.tmax);
    }
    return packed;
}

}  // namespace glslppm::gl_probe
