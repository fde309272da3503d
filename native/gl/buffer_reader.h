// Reads large GPU buffers back to the host through two small staging buffers that stay
// mapped (GL 4.4 buffer storage): the GPU copies one chunk into one while the CPU copies the
// previous chunk out of the other. glGetBufferSubData into pageable memory runs at about
// 1.5 GB/s on the H200 (22 ms for a 1920x1080 film); a copy into mapped host memory runs at
// the bus's speed. Small reads, and drivers without buffer storage, use glGetBufferSubData.
#pragma once

#include <cstddef>

#include <epoxy/gl.h>

namespace glslppm::gl {

class BufferReader {
  public:
    // Every call on the thread whose context owns the buffers.
    BufferReader() = default;
    BufferReader(const BufferReader&) = delete;
    BufferReader& operator=(const BufferReader&) = delete;
    ~BufferReader();  // the staging buffers must have been released (release())

    // `bytes` of `buffer` from `offset` into `out`. Writes by shaders must have been made
    // visible to buffer copies (glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT)) before.
    // `row_bytes` > 0: the bytes are rows of that size, written to `out` in reverse order
    // (an image's top row first on the GPU, its bottom row first for Blender).
    void read(GLuint buffer, std::size_t offset, std::size_t bytes, void* out,
              std::size_t row_bytes = 0);

    // Deletes the staging buffers (the next large read makes them again).
    void release();

    // Bytes of each staging buffer, and the smallest read that goes through them.
    static constexpr std::size_t kChunkBytes = std::size_t(16) << 20;
    static constexpr std::size_t kStagedFrom = std::size_t(1) << 20;

  private:
    bool ensure_staging();
    GLuint staging_[2] = {0, 0};
    const unsigned char* mapped_[2] = {nullptr, nullptr};
    bool unavailable_ = false;  // no buffer storage: glGetBufferSubData always
};

}  // namespace glslppm::gl
