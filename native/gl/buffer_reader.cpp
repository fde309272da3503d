#include "gl/buffer_reader.h"

#include <algorithm>
#include <cassert>
#include <cstring>
#include <string>
#include <utility>

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

// Copies the `bytes` at byte `at` of a `total`-byte image from `from` into `image`: to the
// same place, or (row_bytes > 0) each row to its mirror, counted from the image's end.
void copy_rows(unsigned char* image, std::size_t total, std::size_t at, const unsigned char* from,
               std::size_t bytes, std::size_t row_bytes) {
    if (row_bytes == 0) {
        std::memcpy(image + at, from, bytes);
        return;
    }
    for (std::size_t done = 0; done < bytes; done += row_bytes)
        std::memcpy(image + total - (at + done) - row_bytes, from + done, row_bytes);
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

void BufferReader::read(GLuint buffer, std::size_t offset, std::size_t bytes, void* out,
                        std::size_t row_bytes) {
    if (row_bytes > 0 && (bytes % row_bytes != 0 || row_bytes > kChunkBytes))
        throw GlError("reading a buffer back: " + std::to_string(bytes) +
                      " bytes are not whole rows of " + std::to_string(row_bytes));
    auto* image = static_cast<unsigned char*>(out);
    if (bytes < kStagedFrom || !ensure_staging()) {
        glBindBuffer(GL_COPY_READ_BUFFER, buffer);
        glGetBufferSubData(GL_COPY_READ_BUFFER, static_cast<GLintptr>(offset),
                           static_cast<GLsizeiptr>(bytes), out);
        if (row_bytes > 0)  // in place: swap the rows end for end
            for (std::size_t top = 0, bottom = bytes - row_bytes; top < bottom;
                 top += row_bytes, bottom -= row_bytes)
                std::swap_ranges(image + top, image + top + row_bytes, image + bottom);
        return;
    }
    // Whole rows per chunk, so that each chunk's rows land whole.
    const std::size_t chunk_bytes = row_bytes ? kChunkBytes / row_bytes * row_bytes : kChunkBytes;
    const std::size_t chunks = (bytes + chunk_bytes - 1) / chunk_bytes;
    const auto chunk_size = [&](std::size_t k) { return std::min(chunk_bytes, bytes - k * chunk_bytes); };
    GLsync fences[2] = {nullptr, nullptr};
    const auto issue = [&](std::size_t k) {
        const std::size_t b = k % 2;
        glBindBuffer(GL_COPY_READ_BUFFER, buffer);
        glBindBuffer(GL_COPY_WRITE_BUFFER, staging_[b]);
        glCopyBufferSubData(GL_COPY_READ_BUFFER, GL_COPY_WRITE_BUFFER,
                            static_cast<GLintptr>(offset + k * chunk_bytes), 0,
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
        copy_rows(image, bytes, k * chunk_bytes, mapped_[b], chunk_size(k), row_bytes);
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
