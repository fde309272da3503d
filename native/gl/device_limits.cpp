#include "gl/device_limits.h"

#include <epoxy/gl.h>

#include <map>
#include <mutex>

#include "gl/gl_thread.h"

namespace glslppm::gl {
namespace {

DeviceLimits ask_device(int device_index) {
    DeviceLimits limits;
    GlThread thread(device_index);
    thread.call([&] {
        GLint64 largest = 0;
        glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &largest);
        limits.max_storage_buffer_bytes = largest;
        if (epoxy_has_gl_extension("GL_NVX_gpu_memory_info")) {
            GLint kib = 0;
            glGetIntegerv(0x9048, &kib);  // GPU_MEMORY_INFO_TOTAL_AVAILABLE_MEMORY_NVX
            // Mesa's llvmpipe answers with a negative number: unknown, then.
            limits.memory_bytes = kib > 0 ? static_cast<std::int64_t>(kib) * 1024 : 0;
        }
    });
    limits.software = thread.info().software;
    limits.renderer = thread.info().renderer;
    limits.vendor = thread.info().vendor;
    return limits;
}

}  // namespace

const DeviceLimits& device_limits(int device_index) {
    // std::map: its elements stay where they are as others are added, so the references
    // handed out stay valid. The lock is held while asking, so that two threads asking for
    // one new device open it once.
    static std::mutex mutex;
    static std::map<int, DeviceLimits> known;
    const std::lock_guard lock(mutex);
    auto found = known.find(device_index);
    if (found == known.end()) found = known.emplace(device_index, ask_device(device_index)).first;
    return found->second;
}

}  // namespace glslppm::gl
