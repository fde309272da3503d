#include "gl/egl_context.h"

#include "gl/object_counts.h"

#include <dlfcn.h>
#include <epoxy/gl.h>

#include <algorithm>
#include <cstdlib>
#include <map>
#include <mutex>
#include <sstream>

#include "gl/shader_program.h"

// libepoxy 1.5's generated headers predate these; the values are from Khronos' eglext.h.
#ifndef EGL_DRM_RENDER_NODE_FILE_EXT
#define EGL_DRM_RENDER_NODE_FILE_EXT 0x3377
#endif
#ifndef EGL_CUDA_DEVICE_NV
#define EGL_CUDA_DEVICE_NV 0x323A
#endif

namespace glslppm::gl {
namespace {

constexpr const char* kInstallHint =
    "install a GPU driver, or Debian's libegl-mesa0 and libgl1-mesa-dri for software "
    "rendering";

bool has_extension(const char* list, const char* name) {
    if (list == nullptr) return false;
    const std::string needle = name;
    std::istringstream words(list);
    for (std::string word; words >> word;) {
        if (word == needle) return true;
    }
    return false;
}

// libepoxy aborts the process when libEGL cannot be loaded; check first so the user gets a
// GlError with a fix instead of a crash.
void require_libegl() {
    if (!libegl_loaded()) {
        throw GlError(
            "libEGL.so.1 could not be loaded: install Debian's libegl1 (and a GPU driver, or "
            "libegl-mesa0 and libgl1-mesa-dri for software rendering)");
    }
}

const char* client_extensions() {
    // NULL (EGL_BAD_DISPLAY) when EGL_EXT_client_extensions is unsupported.
    const char* ext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (ext == nullptr) eglGetError();
    return ext;
}

// eglTerminate destroys every context of a display, also those of other EglContexts in this
// process and of the host application (Blender may use EGL itself). So displays are counted:
// one is terminated only when our last context on it goes and we were the ones to initialize
// it. A display someone else initialized first is never terminated by us.
struct DisplayRef {
    int count = 0;
    bool owned = false;  // initialized by us, so ours to terminate
};
std::mutex g_display_mutex;
std::map<EGLDisplay, DisplayRef>& display_refs() {
    static std::map<EGLDisplay, DisplayRef> refs;
    return refs;
}

// Initializes the display (or takes a reference to it); false with `why` on failure.
bool acquire_display(EGLDisplay display, std::string& why) {
    std::lock_guard lock(g_display_mutex);
    auto& refs = display_refs();
    auto it = refs.find(display);
    if (it != refs.end()) {
        ++it->second.count;
        return true;
    }
    // EGL_VERSION is readable only on an initialized display.
    const bool already_initialized = eglQueryString(display, EGL_VERSION) != nullptr;
    if (!already_initialized) eglGetError();
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display, &major, &minor)) {
        why = std::string("eglInitialize failed (") + egl_error_name(eglGetError()) + ")";
        return false;
    }
    refs[display] = DisplayRef{1, !already_initialized};
    return true;
}

void release_display(EGLDisplay display) {
    std::lock_guard lock(g_display_mutex);
    auto& refs = display_refs();
    auto it = refs.find(display);
    if (it == refs.end()) return;
    if (--it->second.count > 0) return;
    const bool owned = it->second.owned;
    refs.erase(it);
    // Measured on llvmpipe: terminating and re-initializing 100 times keeps resident memory
    // flat (tests/native/gl_context_test.cpp), so no display is kept alive beyond its use.
    if (owned) eglTerminate(display);
}

std::string device_count(std::size_t n) {
    return std::to_string(n) + (n == 1 ? " device" : " devices");
}

std::string describe(const std::vector<DeviceInfo>& devices) {
    std::string out;
    for (const DeviceInfo& d : devices) {
        if (!out.empty()) out += ", ";
        out += std::to_string(d.index) + " (" + d.name + ")";
    }
    return out.empty() ? std::string("none") : out;
}

int parse_device_env(const char* value, const std::vector<DeviceInfo>& devices) {
    char* end = nullptr;
    const long index = std::strtol(value, &end, 10);
    if (end == value || *end != '\0') {
        throw GlError(std::string("GLSLPPM_DEVICE=") + value +
                      " is not a device index; EGL lists " + device_count(devices.size()) + ": " +
                      describe(devices));
    }
    if (index < 0 || index >= static_cast<long>(devices.size())) {
        throw GlError(std::string("GLSLPPM_DEVICE=") + value + " but EGL lists " +
                      device_count(devices.size()) + ": " + describe(devices));
    }
    return static_cast<int>(index);
}

}  // namespace

const char* egl_error_name(EGLint error) {
    switch (error) {
        case EGL_SUCCESS:
            return "EGL_SUCCESS";
        case EGL_NOT_INITIALIZED:
            return "EGL_NOT_INITIALIZED";
        case EGL_BAD_ACCESS:
            return "EGL_BAD_ACCESS";
        case EGL_BAD_ALLOC:
            return "EGL_BAD_ALLOC";
        case EGL_BAD_ATTRIBUTE:
            return "EGL_BAD_ATTRIBUTE";
        case EGL_BAD_CONFIG:
            return "EGL_BAD_CONFIG";
        case EGL_BAD_CONTEXT:
            return "EGL_BAD_CONTEXT";
        case EGL_BAD_CURRENT_SURFACE:
            return "EGL_BAD_CURRENT_SURFACE";
        case EGL_BAD_DISPLAY:
            return "EGL_BAD_DISPLAY";
        case EGL_BAD_MATCH:
            return "EGL_BAD_MATCH";
        case EGL_BAD_NATIVE_PIXMAP:
            return "EGL_BAD_NATIVE_PIXMAP";
        case EGL_BAD_NATIVE_WINDOW:
            return "EGL_BAD_NATIVE_WINDOW";
        case EGL_BAD_PARAMETER:
            return "EGL_BAD_PARAMETER";
        case EGL_BAD_SURFACE:
            return "EGL_BAD_SURFACE";
        case EGL_CONTEXT_LOST:
            return "EGL_CONTEXT_LOST";
        default:
            return "unknown EGL error";
    }
}

bool is_software_device(int device_index) {
    const std::vector<DeviceInfo> devices = list_devices();
    if (device_index < 0) {
        if (const char* env = std::getenv("GLSLPPM_DEVICE"); env != nullptr && *env != 0)
            device_index = parse_device_env(env, devices);
    }
    if (device_index >= 0) {
        if (device_index >= static_cast<int>(devices.size()))
            throw GlError("device index " + std::to_string(device_index) + " but EGL lists " +
                          device_count(devices.size()) + ": " + describe(devices));
        return devices[device_index].software;
    }
    return std::none_of(devices.begin(), devices.end(),
                        [](const DeviceInfo& d) { return !d.software; });
}

std::vector<DeviceInfo> list_devices() {
    require_libegl();
    const char* client = client_extensions();
    if (!has_extension(client, "EGL_EXT_device_enumeration") &&
        !has_extension(client, "EGL_EXT_device_base")) {
        return {};
    }
    EGLint count = 0;
    if (!eglQueryDevicesEXT(0, nullptr, &count) || count <= 0) {
        eglGetError();
        return {};
    }
    std::vector<EGLDeviceEXT> handles(static_cast<std::size_t>(count));
    if (!eglQueryDevicesEXT(count, handles.data(), &count)) {
        eglGetError();
        return {};
    }
    std::vector<DeviceInfo> devices;
    for (EGLint i = 0; i < count; ++i) {
        DeviceInfo d;
        d.index = i;
        const char* ext = eglQueryDeviceStringEXT(handles[i], EGL_EXTENSIONS);
        d.extensions = ext != nullptr ? ext : "";
        d.software = has_extension(ext, "EGL_MESA_device_software");
        if (has_extension(ext, "EGL_EXT_device_drm_render_node")) {
            const char* node = eglQueryDeviceStringEXT(handles[i], EGL_DRM_RENDER_NODE_FILE_EXT);
            if (node != nullptr) d.name = node;
        }
        if (d.name.empty() && has_extension(ext, "EGL_EXT_device_drm")) {
            const char* file = eglQueryDeviceStringEXT(handles[i], EGL_DRM_DEVICE_FILE_EXT);
            if (file != nullptr) d.name = file;
        }
        if (d.name.empty() && has_extension(ext, "EGL_NV_device_cuda")) {
            EGLAttrib cuda = -1;
            if (eglQueryDeviceAttribEXT(handles[i], EGL_CUDA_DEVICE_NV, &cuda)) {
                d.name = "CUDA device " + std::to_string(cuda);
            }
        }
        if (d.name.empty()) d.name = d.software ? "software" : "unnamed device";
        eglGetError();  // a failed query above must not leak into later error reports
        devices.push_back(std::move(d));
    }
    return devices;
}

EglContext::EglContext(int device_index) {
    require_libegl();
    const char* client = client_extensions();
    const bool platform_base = has_extension(client, "EGL_EXT_platform_base");
    std::vector<std::string> tried;

    // Which devices to try, in order. An index the user chose is the only one tried.
    const std::vector<DeviceInfo> devices = list_devices();
    std::vector<int> order;
    bool user_choice = false;
    if (device_index >= 0) {
        if (device_index >= static_cast<int>(devices.size())) {
            throw GlError("device index " + std::to_string(device_index) + " but EGL lists " +
                          device_count(devices.size()) + ": " + describe(devices));
        }
        order.push_back(device_index);
        user_choice = true;
    } else if (const char* env = std::getenv("GLSLPPM_DEVICE"); env != nullptr && *env != 0) {
        order.push_back(parse_device_env(env, devices));
        user_choice = true;
    } else {
        for (const DeviceInfo& d : devices) {
            if (!d.software) order.push_back(d.index);
        }
        for (const DeviceInfo& d : devices) {
            if (d.software) order.push_back(d.index);
        }
    }

    if (!order.empty() && platform_base && has_extension(client, "EGL_EXT_platform_device")) {
        std::vector<EGLDeviceEXT> handles(devices.size());
        EGLint count = 0;
        eglQueryDevicesEXT(static_cast<EGLint>(handles.size()), handles.data(), &count);
        for (int index : order) {
            if (index >= count) continue;
            EGLDisplay display =
                eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, handles[index], nullptr);
            try {
                if (display == EGL_NO_DISPLAY) {
                    throw GlError(std::string("eglGetPlatformDisplayEXT failed (") +
                                  egl_error_name(eglGetError()) + ")");
                }
                info_.platform = "device";
                info_.device_index = index;
                info_.device_name = devices[index].name;
                create_on(display);
                return;
            } catch (const GlError& e) {
                if (user_choice) {
                    throw GlError("EGL device " + std::to_string(index) + " (" +
                                  devices[index].name + "): " + e.what());
                }
                tried.push_back("device " + std::to_string(index) + " (" + devices[index].name +
                                "): " + e.what());
            }
        }
    } else if (devices.empty()) {
        tried.push_back("device platform: EGL lists no devices");
    } else {
        tried.push_back("device platform: EGL_EXT_platform_device is missing");
    }

    if (platform_base && has_extension(client, "EGL_MESA_platform_surfaceless")) {
        EGLDisplay display =
            eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
        try {
            if (display == EGL_NO_DISPLAY) {
                throw GlError(std::string("eglGetPlatformDisplayEXT failed (") +
                              egl_error_name(eglGetError()) + ")");
            }
            info_.platform = "surfaceless";
            info_.device_index = -1;
            info_.device_name = "surfaceless";
            create_on(display);
            return;
        } catch (const GlError& e) {
            tried.push_back(std::string("surfaceless platform: ") + e.what());
        }
    } else {
        tried.push_back("surfaceless platform: EGL_MESA_platform_surfaceless is missing");
    }

    std::string detail;
    for (const std::string& t : tried) detail += (detail.empty() ? "" : "; ") + t;
    throw GlError(std::string("EGL found no GPU and no software renderer that gives OpenGL 4.3 (") +
                  detail + "): " + kInstallHint);
}

void EglContext::create_on(EGLDisplay display) {
    std::string why;
    if (!acquire_display(display, why)) throw GlError(why);
    display_ = display;
    display_referenced_ = true;
    try {
        if (!eglBindAPI(EGL_OPENGL_API)) {
            throw GlError(std::string("eglBindAPI(EGL_OPENGL_API) failed (") +
                          egl_error_name(eglGetError()) + "): the driver has no desktop OpenGL");
        }
        const char* ext = eglQueryString(display, EGL_EXTENSIONS);
        const bool surfaceless = has_extension(ext, "EGL_KHR_surfaceless_context");
        // EGL_SURFACE_TYPE defaults to EGL_WINDOW_BIT, which device-platform configs lack.
        const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE,
                                         surfaceless ? 0 : EGL_PBUFFER_BIT, EGL_NONE};
        EGLConfig config = nullptr;
        EGLint num_configs = 0;
        if (!eglChooseConfig(display, config_attribs, &config, 1, &num_configs) ||
            num_configs < 1) {
            throw GlError(std::string("no EGL config renders desktop OpenGL (") +
                          egl_error_name(eglGetError()) + ")");
        }
        const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                          4,
                                          EGL_CONTEXT_MINOR_VERSION,
                                          3,
                                          EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                          EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                          EGL_NONE};
        context_ = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attribs);
        if (context_ != EGL_NO_CONTEXT) count_gl_objects(GlObject::Context, 1);
        if (context_ == EGL_NO_CONTEXT) {
            throw GlError(std::string("no OpenGL 4.3 core context (") +
                          egl_error_name(eglGetError()) +
                          "): glslppm needs OpenGL 4.3 compute shaders; update the GPU driver");
        }
        if (!surfaceless) {
            const EGLint pbuffer_attribs[] = {EGL_WIDTH, 1, EGL_HEIGHT, 1, EGL_NONE};
            surface_ = eglCreatePbufferSurface(display, config, pbuffer_attribs);
            if (surface_ == EGL_NO_SURFACE) {
                throw GlError(std::string("neither EGL_KHR_surfaceless_context nor a pbuffer (") +
                              egl_error_name(eglGetError()) + ")");
            }
        }
        if (!eglMakeCurrent(display, surface_, surface_, context_)) {
            throw GlError(std::string("eglMakeCurrent failed (") + egl_error_name(eglGetError()) +
                          ")");
        }
        auto gl_string = [](GLenum name) {
            const auto* s = reinterpret_cast<const char*>(glGetString(name));
            return std::string(s != nullptr ? s : "");
        };
        info_.renderer = gl_string(GL_RENDERER);
        info_.version = gl_string(GL_VERSION);
        info_.vendor = gl_string(GL_VENDOR);
        GLint major = 0, minor = 0;
        glGetIntegerv(GL_MAJOR_VERSION, &major);
        glGetIntegerv(GL_MINOR_VERSION, &minor);
        if (major * 10 + minor < 43) {
            throw GlError("the driver gives OpenGL " + info_.version +
                          " but glslppm needs 4.3 compute shaders; update the GPU driver");
        }
        const bool software_renderer = info_.renderer.find("llvmpipe") != std::string::npos ||
                                       info_.renderer.find("softpipe") != std::string::npos ||
                                       info_.renderer.find("SWR") != std::string::npos;
        info_.software = software_renderer;
        programs_ = std::make_unique<ProgramCache>();
    } catch (...) {
        release();
        throw;
    }
}

ProgramCache& EglContext::programs() { return *programs_; }

void EglContext::release() noexcept {
    programs_.reset();  // deletes GL programs while the context is still current
    if (display_ != EGL_NO_DISPLAY) {
        if (eglGetCurrentContext() == context_ && context_ != EGL_NO_CONTEXT) {
            eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        }
        if (context_ != EGL_NO_CONTEXT) {
            eglDestroyContext(display_, context_);
            count_gl_objects(GlObject::Context, -1);
        }
        if (surface_ != EGL_NO_SURFACE) eglDestroySurface(display_, surface_);
        if (display_referenced_) release_display(display_);
    }
    context_ = EGL_NO_CONTEXT;
    surface_ = EGL_NO_SURFACE;
    display_ = EGL_NO_DISPLAY;
    display_referenced_ = false;
}

EglContext::~EglContext() { release(); }

bool libegl_loaded() {
    static const bool loaded = [] {
        void* handle = dlopen("libEGL.so.1", RTLD_LAZY | RTLD_GLOBAL);
        return handle != nullptr;  // kept loaded for the process lifetime
    }();
    return loaded;
}

}  // namespace glslppm::gl
