// The pipeline's buffers and textures: made, replaced, released (render/pipeline.h).
#include <algorithm>

#include "gl/object_counts.h"
#include "render/pipeline.h"
#include "render/tiled_render.h"

namespace glslppm {

std::size_t Renderer::Gpu::largest_block(bool per_pixel) const {
    GLint64 largest = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &largest);
    return per_pixel ? capped_block_bytes(largest, settings)
                     : static_cast<std::size_t>(std::max<GLint64>(largest, 0));
}

void Renderer::Gpu::require_fits(std::size_t bytes, const char* what, bool per_pixel) const {
    const std::size_t largest = largest_block(per_pixel);
    if (largest > 0 && bytes > largest)
        throw gl::GlError(std::string(what) + " needs " + std::to_string(bytes >> 20) +
                          " MiB, more than this GPU's largest storage buffer (" +
                          std::to_string(largest >> 20) +
                          " MiB): lower the resolution or the photons per pass, or render "
                          "in tiles (render_tiled, glslppm-render)");
}

GLuint Renderer::Gpu::make_buffer(GLuint binding, std::size_t bytes, const void* data,
                                  const char* what) {
    throw_if_cancelled(setup_cancel);  // large uploads take a while on llvmpipe
    GLuint id = 0;
    glGenBuffers(1, &id);
    gl::count_gl_objects(gl::GlObject::Buffer, 1);
    buffers.ssbos.push_back(id);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, id);
    while (glGetError() != GL_NO_ERROR) {
    }
    require_fits(bytes, what);
    glBufferData(GL_SHADER_STORAGE_BUFFER,
                 static_cast<GLsizeiptr>(std::max<std::size_t>(bytes, 16)), data, GL_DYNAMIC_COPY);
    if (glGetError() == GL_OUT_OF_MEMORY)
        throw gl::GlError("out of GPU memory allocating " + std::string(what) + " (" +
                          std::to_string(bytes >> 20) +
                          " MiB): lower the resolution or "
                          "the photons per pass");
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, id);
    buffers.bytes += bytes;
    return id;
}

void Renderer::Gpu::replace_buffer(GLuint id, std::size_t bytes, const void* data,
                                   const char* what) {
    require_fits(bytes, what);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, id);
    glBufferData(GL_SHADER_STORAGE_BUFFER,
                 static_cast<GLsizeiptr>(std::max<std::size_t>(bytes, 16)), data, GL_DYNAMIC_COPY);
}

void Renderer::Gpu::upload_atlas(const TextureAtlas& atlas) {
    GLuint* atlases = buffers.atlases;
    glGenTextures(2, atlases);
    gl::count_gl_objects(gl::GlObject::Texture, 2);
    for (int e = 0; e < 2; ++e) {
        const bool has = atlas.layers[e] > 0;
        const glm::ivec2 size = has ? atlas.layer_size[e] : glm::ivec2(1);
        const int layers = has ? atlas.layers[e] : 1;
        glActiveTexture(GL_TEXTURE0 + e);
        glBindTexture(GL_TEXTURE_2D_ARRAY, atlases[e]);
        while (glGetError() != GL_NO_ERROR) {
        }
        // sRGB images as UNORM bytes, not GL_SRGB8_ALPHA8: the shaders filter the bytes and
        // then decode, as Cycles does (shaders/common/textures.glsl).
        glTexStorage3D(GL_TEXTURE_2D_ARRAY, 1, e == 0 ? GL_RGBA8 : GL_RGBA32F, size.x, size.y,
                       layers);
        if (glGetError() != GL_NO_ERROR)
            throw gl::GlError("out of GPU memory for the scene's images (" +
                              std::to_string(layers) + " layers of " + std::to_string(size.x) +
                              "x" + std::to_string(size.y) + "): use fewer or smaller images");
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        if (has) {
            glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
            glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, 0, size.x, size.y, layers, GL_RGBA,
                            e == 0 ? GL_UNSIGNED_BYTE : GL_FLOAT,
                            e == 0 ? static_cast<const void*>(atlas.srgb8.data())
                                   : static_cast<const void*>(atlas.linear.data()));
            buffers.bytes += std::size_t(size.x) * size.y * layers * (e == 0 ? 4 : 16);
        }
    }
    glActiveTexture(GL_TEXTURE0);
}

void Renderer::Gpu::upload_frame() {
    glBindBuffer(GL_UNIFORM_BUFFER, buffers.frame);
    glBufferSubData(GL_UNIFORM_BUFFER, 0, sizeof(FrameBlock), &scene.frame);
}

Counters Renderer::Gpu::read_counters() {
    Counters c{};
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffers.counters);
    glGetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, sizeof(Counters), &c);
    return c;
}

void Renderer::Gpu::release() {
    PipelineBuffers& b = buffers;
    b.reader.release();
    if (!b.ssbos.empty()) glDeleteBuffers(static_cast<GLsizei>(b.ssbos.size()), b.ssbos.data());
    gl::count_gl_objects(gl::GlObject::Buffer, -static_cast<std::int64_t>(b.ssbos.size()));
    b.ssbos.clear();
    if (b.frame) {
        glDeleteBuffers(1, &b.frame);
        gl::count_gl_objects(gl::GlObject::Buffer, -1);
    }
    b.frame = 0;
    if (timer.queries[0]) {
        glDeleteQueries(5, timer.queries);
        gl::count_gl_objects(gl::GlObject::Query, -5);
    }
    timer.queries[0] = 0;
    if (b.atlases[0]) {
        glDeleteTextures(2, b.atlases);
        gl::count_gl_objects(gl::GlObject::Texture, -2);
    }
    b.atlases[0] = b.atlases[1] = 0;
}

}  // namespace glslppm
