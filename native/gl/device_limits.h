// What a render may allocate on an EGL device, asked once per device for the process: tile
// planning asks before every final render, and opening a context of its own for that costs
// about 75 ms on llvmpipe.
#pragma once

#include <cstdint>
#include <string>

namespace glslppm::gl {

struct DeviceLimits {
    std::int64_t max_storage_buffer_bytes = 0;  // GL_MAX_SHADER_STORAGE_BLOCK_SIZE; 0: none said
    std::int64_t memory_bytes = 0;  // GL_NVX_gpu_memory_info's total; 0: unknown (llvmpipe)
    bool software = false;          // EGL_MESA_device_software
    std::string renderer, vendor;   // GL_RENDERER, GL_VENDOR
};

// The limits of device_index (as EglContext's: -1 is the default device). The first call for
// an index asks the device on a GL thread of its own (the caller's thread may have another
// GL context current, Blender's UI, where making ours current fails with EGL_BAD_ACCESS);
// later calls return that answer. Thread-safe. A device that cannot be opened throws
// GlError, and is asked again next time.
const DeviceLimits& device_limits(int device_index);

}  // namespace glslppm::gl
