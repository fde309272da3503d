#include "gl/buffer_reader.h"

#include <algorithm>
#include <cassert>
#include <cstring>
#include <string>

#include "gl/object_counts.h"
#include "gl/egl_context.h"

namespace glslppm::gl {
namespace {

// Waits for a fence the host needs (a read-back): flushes once, then waits in slices.
void wait_for(GLsync fence) {
    GLbitfield flags = GL_SYNC_FLUSH_COMMANDS_BIT;
    for (;;) {
        const GLenum status = glClientWaitSync(fence, flags, 100'000'000);  // 0.1 s
        if (status == GL_ALREADY_SIGNALED || status == GL_CONDITION_SATISFIED) return;
        if (status == GL_WAIT_FAILED) {
            glDeleteSync(fence);
            throw GlError("reading a buffer back: the GPU's fence failed (glClientWaitSync)");
        }
        flags = 0;
    }
}

}  // namespace

BufferReader::~BufferReader() { assert(staging_[0] == 0 && "release() with the context current"); }

bool BufferReader::ensure_staging() {
    if (staging_[0]) return true;
    if (unavailable_) return false;
    if (epoxy_gl_version() < 44 && !epoxy_has_gl_extension("GL_ARB_buffer_storage")) {
        unavailable_ = true;
        return false;
    }
    // Host memory the CPU reads (client storage), mapped once for good; coherent, so a fence
    // after the copy is all the CPU needs before reading.
    const GLbitfield access = GL_MAP_READ_BIT | GL_MAP_PERSISTENT_BIT | GL_MAP_COHERENT_BIT;
    glGenBuffers(2, staging_);
    count_gl_objects(GlObject::Buffer, 2);
    for (int k = 0; k < 2; ++k) {
        glBindBuffer(GL_COPY_WRITE_BUFFER, staging_[k]);
        glBufferStorage(GL_COPY_WRITE_BUFFER, static_cast<GLsizeiptr>(kChunkBytes), nullptr,
                        access | GL_CLIENT_STORAGE_BIT);
        mapped_[k] = static_cast<const unsigned char*>(glMapBufferRange(
            GL_COPY_WRITE_BUFFER, 0, static_cast<GLsizeiptr>(kChunkBytes), access));
        if (!mapped_[k]) {  // a driver that offers buffer storage but cannot map it so
            release();
            unavailable_ = true;
            return false;
        }
    }
    return true;
}

void BufferReader::read(GLuint buffer, std::size_t offset, std::size_t bytes, void* out) {
    if (bytes < kStagedFrom || !ensure_staging()) {
        glBindBuffer(GL_COPY_READ_BUFFER, buffer);
        glGetBufferSubData(GL_COPY_READ_BUFFER, static_cast<GLintptr>(offset),
                           static_cast<GLsizeiptr>(bytes), out);
        return;
    }
    const std::size_t chunks = (bytes + kChunkBytes - 1) / kChunkBytes;
    const auto chunk_size = [&](std::size_t k) { return std::min(kChunkBytes, bytes - k * kChunkBytes); };
    GLsync fences[2] = {nullptr, nullptr};
    const auto issue = [&](std::size_t k) {
        const std::size_t b = k % 2;
        glBindBuffer(GL_COPY_READ_BUFFER, buffer);
        glBindBuffer(GL_COPY_WRITE_BUFFER, staging_[b]);
        glCopyBufferSubData(GL_COPY_READ_BUFFER, GL_COPY_WRITE_BUFFER,
                            static_cast<GLintptr>(offset + k * kChunkBytes), 0,
                            static_cast<GLsizeiptr>(chunk_size(k)));
        fences[b] = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    };
    // Chunk k + 2 goes into the buffer chunk k has just been copied out of.
    issue(0);
    if (chunks > 1) issue(1);
    for (std::size_t k = 0; k < chunks; ++k) {
        const std::size_t b = k % 2;
        try {
            wait_for(fences[b]);
        } catch (...) {
            if (fences[1 - b]) glDeleteSync(fences[1 - b]);
            throw;
        }
        glDeleteSync(fences[b]);
        fences[b] = nullptr;
        std::memcpy(static_cast<unsigned char*>(out) + k * kChunkBytes, mapped_[b], chunk_size(k));
        if (k + 2 < chunks) issue(k + 2);
    }
}

void BufferReader::release() {
    if (!staging_[0]) return;
    for (int k = 0; k < 2; ++k) {
        if (mapped_[k]) {
            glBindBuffer(GL_COPY_WRITE_BUFFER, staging_[k]);
            glUnmapBuffer(GL_COPY_WRITE_BUFFER);
        }
        mapped_[k] = nullptr;
    }
    glDeleteBuffers(2, staging_);
    count_gl_objects(GlObject::Buffer, -2);
    staging_[0] = staging_[1] = 0;
}

}  // namespace glslppm::gl
