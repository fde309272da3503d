// Headless OpenGL 4.3 core contexts through EGL.
//
// The EGL device platform comes first (EGL_EXT_device_enumeration: one EGLDeviceEXT per
// GPU, so a user can pick a GPU and several can work at once); Mesa's surfaceless platform
// is the fallback. Every entry point goes through libepoxy, which Blender links too.
#pragma once

#include <epoxy/egl.h>

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace glslppm::gl {

class ProgramCache;

// A GL/EGL failure the user can act on: the message says what is missing and how to get it.
class GlError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// One EGL device as EGL_EXT_device_enumeration lists it.
struct DeviceInfo {
    int index = 0;
    std::string name;        // DRM node (/dev/dri/renderD128), "CUDA device 0", or "software"
    std::string extensions;  // the device's extension string
    bool software = false;   // EGL_MESA_device_software (llvmpipe)
};

// Lists the EGL devices; empty when EGL cannot enumerate devices (no extension, no driver).
std::vector<DeviceInfo> list_devices();
// Whether libEGL.so.1 could be loaded. Without it every EGL call through libepoxy aborts the
// process (Blender with it), so EGL calls outside a context's creation ask this first.
bool libegl_loaded();

// Whether the device an EglContext(device_index) would run on is a software rasterizer, known
// before any context exists: -1 resolves as the constructor does (GLSLPPM_DEVICE, else the
// first hardware device); Mesa's surfaceless platform, used where no device is listed, counts
// as software. Throws GlError for an index EGL does not list.
bool is_software_device(int device_index);

// What the context runs on.
struct ContextInfo {
    std::string renderer;   // GL_RENDERER, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
    std::string version;    // GL_VERSION
    std::string vendor;     // GL_VENDOR
    std::string platform;   // "device" or "surfaceless"
    int device_index = -1;  // index into list_devices(); -1 on the surfaceless platform
    std::string device_name;
    bool software = false;  // llvmpipe or another software rasterizer
};

// An OpenGL 4.3 core context, current on the thread that constructed it, with no surface.
// Construct, use and destroy it on one thread (GlThread does that for callers that have a
// GL context of their own).
class EglContext {
  public:
    // device_index -1: GLSLPPM_DEVICE if set, else the first hardware device, else the first
    // device, else Mesa's surfaceless platform. Throws GlError when nothing works.
    explicit EglContext(int device_index = -1);
    ~EglContext();
    EglContext(const EglContext&) = delete;
    EglContext& operator=(const EglContext&) = delete;

    const ContextInfo& info() const { return info_; }
    EGLDisplay display() const { return display_; }
    EGLContext context() const { return context_; }

    // Compiled programs of this context, keyed by (file, defines); destroyed with it.
    ProgramCache& programs();

  private:
    void create_on(EGLDisplay display);
    void release() noexcept;

    EGLDisplay display_ = EGL_NO_DISPLAY;
    EGLContext context_ = EGL_NO_CONTEXT;
    EGLSurface surface_ = EGL_NO_SURFACE;  // a 1x1 pbuffer only without surfaceless support
    bool display_referenced_ = false;
    ContextInfo info_;
    std::unique_ptr<ProgramCache> programs_;
};

// The symbolic name of an EGL error code, e.g. "EGL_BAD_MATCH".
const char* egl_error_name(EGLint error);

}  // namespace glslppm::gl
