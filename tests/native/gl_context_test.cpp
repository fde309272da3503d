// EglContext and GlThread on the real EGL of this machine (llvmpipe here, a GPU elsewhere).
#include <gtest/gtest.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "gl/egl_context.h"
#include "gl/gl_thread.h"

extern char** environ;

namespace glslppm::gl {
namespace {

// Resident set size in bytes, from /proc/self/statm.
long resident_bytes() {
    std::ifstream statm("/proc/self/statm");
    long size = 0, resident = 0;
    statm >> size >> resident;
    return resident * sysconf(_SC_PAGESIZE);
}

// Sets an environment variable for one scope.
class ScopedEnv {
  public:
    ScopedEnv(const char* name, const char* value) : name_(name) {
        if (const char* old = std::getenv(name)) old_ = old, had_ = true;
        setenv(name, value, 1);
    }
    ~ScopedEnv() { had_ ? (void)setenv(name_, old_.c_str(), 1) : (void)unsetenv(name_); }

  private:
    const char* name_;
    std::string old_;
    bool had_ = false;
};

// Runs this test binary again with a gtest filter and extra environment; returns its output.
std::string run_child(const std::string& filter, const std::vector<std::string>& extra_env,
                      int& exit_code) {
    // The child's environment: ours, with the names in extra_env replaced (getenv would
    // find the first of two entries of one name).
    std::vector<std::string> env_strings;
    for (char** e = environ; *e != nullptr; ++e) {
        const std::string entry = *e;
        const std::string name = entry.substr(0, entry.find('='));
        bool replaced = false;
        for (const std::string& x : extra_env) replaced |= x.substr(0, x.find('=')) == name;
        if (!replaced) env_strings.push_back(entry);
    }
    for (const std::string& e : extra_env) env_strings.push_back(e);
    std::vector<char*> envp;
    for (std::string& e : env_strings) envp.push_back(e.data());
    envp.push_back(nullptr);

    std::string exe = "/proc/self/exe";
    std::string filter_arg = "--gtest_filter=" + filter;
    char* argv[] = {exe.data(), filter_arg.data(), nullptr};
    int fds[2];
    if (pipe(fds) != 0) throw std::runtime_error("pipe failed");
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_adddup2(&actions, fds[1], 1);
    posix_spawn_file_actions_adddup2(&actions, fds[1], 2);
    posix_spawn_file_actions_addclose(&actions, fds[0]);
    pid_t pid = 0;
    const int rc = posix_spawn(&pid, "/proc/self/exe", &actions, nullptr, argv, envp.data());
    posix_spawn_file_actions_destroy(&actions);
    close(fds[1]);
    if (rc != 0) throw std::runtime_error("posix_spawn failed");
    std::string output;
    char buffer[4096];
    for (ssize_t n; (n = read(fds[0], buffer, sizeof buffer)) > 0;) output.append(buffer, n);
    close(fds[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    return output;
}

TEST(GlContext, ReportsRendererAndVersion) {
    EglContext context;
    const ContextInfo& info = context.info();
    EXPECT_FALSE(info.renderer.empty());
    EXPECT_FALSE(info.vendor.empty());
    EXPECT_TRUE(info.platform == "device" || info.platform == "surfaceless") << info.platform;
    int major = 0, minor = 0;
    ASSERT_EQ(std::sscanf(info.version.c_str(), "%d.%d", &major, &minor), 2) << info.version;
    EXPECT_GE(major * 10 + minor, 43) << info.version;
    EXPECT_EQ(eglGetCurrentContext(), context.context());
    std::printf("renderer: %s | version: %s | platform: %s, device %d (%s)\n",
                info.renderer.c_str(), info.version.c_str(), info.platform.c_str(),
                info.device_index, info.device_name.c_str());
}

TEST(GlContext, ListsDevicesWithNames) {
    const std::vector<DeviceInfo> devices = list_devices();
    for (const DeviceInfo& d : devices) {
        EXPECT_FALSE(d.name.empty());
        std::printf("EGL device %d: %s%s\n", d.index, d.name.c_str(),
                    d.software ? " (software)" : "");
    }
    // With devices listed, the default context comes from the device platform.
    if (!devices.empty()) {
        EglContext context;
        EXPECT_EQ(context.info().platform, "device");
        EXPECT_GE(context.info().device_index, 0);
    }
}

// GL objects are per context: a fresh context starts from an empty name space, and 100
// create/destroy cycles leave resident memory flat.
TEST(GlContext, HundredCreateDestroyCyclesDoNotLeak) {
    auto cycle = [] {
        EglContext context;
        GLuint buffer = 0;
        glGenBuffers(1, &buffer);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffer);
        glBufferData(GL_SHADER_STORAGE_BUFFER, 1 << 20, nullptr, GL_DYNAMIC_DRAW);
        const GLuint program = glCreateProgram();
        EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
        return std::pair{buffer, program};  // not deleted: destroying the context must
    };
    for (int i = 0; i < 10; ++i) cycle();  // warm up driver caches
    const long before = resident_bytes();
    const auto first = cycle();
    for (int i = 1; i < 100; ++i) {
        const auto names = cycle();
        EXPECT_EQ(names, first) << "cycle " << i << " saw objects of an earlier context";
    }
    const long growth = resident_bytes() - before;
    std::printf("resident memory growth over 100 cycles: %.2f MiB\n", growth / 1048576.0);
    EXPECT_LT(growth, 4L << 20);
}

TEST(GlContext, BadDeviceEnvironmentNamesTheDevices) {
    ScopedEnv env("GLSLPPM_DEVICE", "7");
    const std::size_t count = list_devices().size();
    try {
        EglContext context;
        FAIL() << "no error for GLSLPPM_DEVICE=7";
    } catch (const GlError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("GLSLPPM_DEVICE=7 but EGL lists " + std::to_string(count) +
                               (count == 1 ? " device" : " devices")),
                  std::string::npos)
            << message;
        if (count > 0) {
            EXPECT_NE(message.find("0 ("), std::string::npos) << message;
        }
    }
}

TEST(GlContext, BadDeviceIndexArgumentNamesTheDevices) {
    EXPECT_THROW(EglContext context(1000), GlError);
    ScopedEnv env("GLSLPPM_DEVICE", "gpu0");
    try {
        EglContext context;
        FAIL() << "no error for GLSLPPM_DEVICE=gpu0";
    } catch (const GlError& e) {
        EXPECT_NE(std::string(e.what()).find("not a device index"), std::string::npos) << e.what();
    }
}

// Runs only inside the child process of EglFindingNothingSaysWhatToInstall.
TEST(GlContextChild, PrintsCreationError) {
    if (std::getenv("GLSLPPM_TEST_CHILD") == nullptr) GTEST_SKIP() << "child process only";
    try {
        EglContext context;
        std::printf("CHILD-CREATED %s\n", context.info().renderer.c_str());
    } catch (const GlError& e) {
        std::printf("CHILD-ERROR %s\n", e.what());
    }
}

TEST(GlContext, EglFindingNothingSaysWhatToInstall) {
    // glvnd loads no vendor library, so EGL has no devices and no platforms.
    int exit_code = -1;
    const std::string output = run_child(
        "GlContextChild.PrintsCreationError",
        {"GLSLPPM_TEST_CHILD=1", "__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent/egl_vendor.json",
         "__EGL_VENDOR_LIBRARY_DIRS=/nonexistent", "EGL_PLATFORM=surfaceless"},
        exit_code);
    EXPECT_EQ(exit_code, 0) << output;
    EXPECT_NE(output.find("CHILD-ERROR EGL found no GPU and no software renderer"),
              std::string::npos)
        << output;
    EXPECT_NE(output.find("install a GPU driver, or Debian's libegl-mesa0 and libgl1-mesa-dri"),
              std::string::npos)
        << output;
}

TEST(GlThread, RunsTasksOnItsOwnThreadWithItsContext) {
    GlThread gl;
    EXPECT_FALSE(gl.info().renderer.empty());
    const EGLContext caller_context = eglGetCurrentContext();
    const auto [thread_id, current] = gl.call([] {
        return std::pair{std::this_thread::get_id(), eglGetCurrentContext()};
    });
    EXPECT_NE(thread_id, std::this_thread::get_id());
    EXPECT_NE(current, EGL_NO_CONTEXT);
    EXPECT_EQ(eglGetCurrentContext(), caller_context);  // the caller's state is untouched
    const std::string renderer = gl.call(
        [] { return std::string(reinterpret_cast<const char*>(glGetString(GL_RENDERER))); });
    EXPECT_EQ(renderer, gl.info().renderer);
    // Nested call from the GL thread runs inline instead of deadlocking.
    EXPECT_EQ(gl.call([&gl] { return gl.call([] { return 42; }); }), 42);
}

TEST(GlThread, PropagatesExceptionsAndKeepsWorking) {
    GlThread gl;
    EXPECT_THROW(gl.call([]() -> int { throw std::logic_error("task failed"); }), std::logic_error);
    int ran = 0;
    gl.call([&ran] { ran = 1; });
    EXPECT_EQ(ran, 1);
}

TEST(GlThread, ConstructionErrorReachesTheCaller) { EXPECT_THROW(GlThread gl(1000), GlError); }

TEST(GlThread, TwoContextsOnOneDisplayCoexist) {
    // eglTerminate of one display must not break the other context on it.
    auto a = std::make_unique<GlThread>();
    GlThread b;
    a.reset();
    const GLenum error = b.call([] {
        GLuint buffer = 0;
        glGenBuffers(1, &buffer);
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, buffer);
        glBufferData(GL_SHADER_STORAGE_BUFFER, 64, nullptr, GL_DYNAMIC_DRAW);
        glDeleteBuffers(1, &buffer);
        return glGetError();
    });
    EXPECT_EQ(error, static_cast<GLenum>(GL_NO_ERROR));
}

}  // namespace
}  // namespace glslppm::gl
