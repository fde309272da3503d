#include "gl/device_limits.h"

#include <epoxy/gl.h>
#include <gtest/gtest.h>

#include <chrono>
#include <thread>
#include <vector>

#include "gl/gl_thread.h"
#include "render/tiled_render.h"

using namespace glslppm;

TEST(DeviceLimits, AnswersAsAContextOfItsOwnDoes) {
    gl::GlThread thread(-1);
    const GLint64 largest = thread.call([] {
        GLint64 v = 0;
        glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &v);
        return v;
    });
    const gl::DeviceLimits& limits = gl::device_limits(-1);
    EXPECT_GT(largest, 0);
    EXPECT_EQ(limits.max_storage_buffer_bytes, largest);
    EXPECT_EQ(limits.renderer, thread.info().renderer);
    EXPECT_EQ(limits.software, thread.info().software);
}

TEST(DeviceLimits, AskedOncePerDeviceFromManyThreads) {
    // Device 0 is not asked by the other tests of this program before this one.
    std::vector<const gl::DeviceLimits*> seen(8, nullptr);
    std::vector<std::thread> threads;
    for (std::size_t i = 0; i < seen.size(); ++i)
        threads.emplace_back([&seen, i] { seen[i] = &gl::device_limits(0); });
    for (std::thread& t : threads) t.join();
    for (const gl::DeviceLimits* s : seen) EXPECT_EQ(s, seen[0]);
    EXPECT_GT(seen[0]->max_storage_buffer_bytes, 0);
    EXPECT_EQ(&gl::device_limits(0), seen[0]);
}

TEST(DeviceLimits, TilePlanningOpensNoContextOnceAsked) {
    Scene scene;
    RenderSettings settings;
    settings.width = 3840;
    settings.height = 2160;
    plan_tiles(scene, settings);  // asks the device, if not yet asked
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < 10; ++i) plan_tiles(scene, settings);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    // Opening a context costs about 75 ms on llvmpipe; ten plans from the cache cost
    // microseconds (5 ms leaves room for a loaded machine).
    EXPECT_LT(ms, 5.0);
}

TEST(DeviceLimits, ADeviceThatCannotOpenThrowsEachTime) {
    EXPECT_THROW(gl::device_limits(1000), gl::GlError);
    EXPECT_THROW(gl::device_limits(1000), gl::GlError);
}
