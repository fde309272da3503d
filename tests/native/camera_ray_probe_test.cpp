// The camera ray of shaders/common/camera.glsl (the one eye_trace.comp casts), run on the
// real driver through shaders/tests/camera_probe.comp, held to the CPU's camera_ray_at
// (native/render/camera_ray.h, which the automatic radius looks through), with the Frame
// that frame_camera fills: perspective with a lens shift, non-square pixels, orthographic,
// depth of field and a render region, at pixel corners, centres and sub-pixel offsets.
#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "gl/shader_program.h"
#include "gl_probe.h"
#include "render/camera_ray.h"
#include "render/scene_preparation.h"

namespace glslppm {
namespace {

struct Case {
    std::string name;
    Camera camera;
    int width, height;
};

// The Frame of a camera at an image size, as prepare_scene fills its camera fields.
FrameBlock frame_of(const Case& c) {
    RenderSettings settings;
    settings.width = c.width;
    settings.height = c.height;
    settings.initial_radius = 0.01f;  // no automatic radius: no scene needed
    FrameBlock frame{};
    SceneBounds bounds{glm::vec3(-1.0f), glm::vec3(1.0f)};
    frame_camera(c.camera, settings, PackedBvh{}, bounds, frame);
    frame.image_width = static_cast<std::uint32_t>(c.width);
    frame.image_height = static_cast<std::uint32_t>(c.height);
    return frame;
}

std::vector<glm::vec4> run_probe(const FrameBlock& frame, bool depth_of_field,
                                 const std::vector<glm::vec4>& points) {
    return gl_probe::gl_thread().call([&] {
        gl::Defines defines;
        if (depth_of_field) defines.push_back({"HAS_DEPTH_OF_FIELD", "1"});
        gl::ComputeProgram program("tests/camera_probe.comp", defines);
        GLuint ubo = 0;
        glGenBuffers(1, &ubo);
        glBindBuffer(GL_UNIFORM_BUFFER, ubo);
        glBufferData(GL_UNIFORM_BUFFER, sizeof frame, &frame, GL_STATIC_DRAW);
        glBindBufferBase(GL_UNIFORM_BUFFER, BINDING_FRAME, ubo);
        std::vector<glm::vec4> out;
        {
            const gl_probe::Buffers buffers{{3, points.data(), points.size() * 16},
                                            {4, nullptr, points.size() * 32}};
            program.use();
            glUniform1ui(program.uniform("u_count"), static_cast<GLuint>(points.size()));
            gl_probe::dispatch_items(points.size());
            out = buffers.read<glm::vec4>(1, 2 * points.size());
        }
        glDeleteBuffers(1, &ubo);
        return out;
    });
}

// Every pixel corner, centre and a random sub-pixel offset on a coarse grid over the image
// (its edges included), each with random lens numbers.
std::vector<glm::vec4> film_points(int width, int height, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<glm::vec4> points;
    for (int y = 0; y < height; y += std::max(1, height / 17))
        for (int x = 0; x < width; x += std::max(1, width / 23))
            for (const float j : {0.0f, 0.5f, u(rng), 0.99999994f})
                points.emplace_back(float(x) + j, float(y) + u(rng), u(rng), u(rng));
    points.emplace_back(float(width), float(height), 0.5f, 0.5f);  // the far corner
    return points;
}

Camera placed_camera() {
    Camera c;
    // Turned about two axes and moved away from the origin, as a scene's camera is.
    const glm::mat4 turn = glm::mat4(glm::vec4(0.8f, 0.0f, -0.6f, 0.0f),
                                     glm::vec4(0.36f, 0.8f, 0.48f, 0.0f),
                                     glm::vec4(0.48f, -0.6f, 0.64f, 0.0f),
                                     glm::vec4(3.0f, 1.5f, -7.25f, 1.0f));
    c.to_world = turn;
    c.fov_x = 0.9f;
    return c;
}

TEST(CameraRayGlsl, EqualsCpuCameraRay) {
    std::vector<Case> cases;
    {
        Case c{"perspective, shifted", placed_camera(), 160, 90};
        c.camera.shift_x = 0.1f;
        c.camera.shift_y = -0.05f;
        cases.push_back(c);
    }
    {
        Case c{"perspective, tall, non-square pixels", placed_camera(), 90, 160};
        c.camera.pixel_aspect = 1.25f;
        cases.push_back(c);
    }
    {
        Case c{"orthographic, shifted", placed_camera(), 120, 80};
        c.camera.projection = Projection::Orthographic;
        c.camera.ortho_scale = 3.0f;
        c.camera.shift_x = -0.2f;
        cases.push_back(c);
    }
    {
        Case c{"depth of field", placed_camera(), 128, 96};
        c.camera.aperture_radius = 0.2f;
        c.camera.focus_distance = 3.5f;
        cases.push_back(c);
    }
    {
        Case c{"render region", placed_camera(), 100, 60};
        c.camera.full_width = 400;
        c.camera.full_height = 300;
        c.camera.region_x = 250;
        c.camera.region_y = 40;
        cases.push_back(c);
    }
    std::uint32_t seed = 11;
    for (const Case& c : cases) {
        const FrameBlock frame = frame_of(c);
        const bool lens = c.camera.projection == Projection::Perspective &&
                          c.camera.aperture_radius > 0.0f;
        const std::vector<glm::vec4> points = film_points(c.width, c.height, ++seed);
        const std::vector<glm::vec4> gpu = run_probe(frame, lens, points);
        // GLSL requires neither correctly rounded division nor exact cos and sin (the lens
        // point), so the two agree to rounding: within 2^-20 of the values' magnitude (a few
        // ulps). A wrong offset, flip, shift or lens is off by a pixel's footprint or more:
        // 1e-2 of the film here, 10,000 times the bound.
        double worst = 0.0;
        int off = 0;
        for (std::size_t i = 0; i < points.size(); ++i) {
            const glm::vec4 p = points[i];
            const Ray cpu = camera_ray_at(frame, glm::vec2(p), glm::vec2(p.z, p.w), lens);
            const glm::vec3 got_o(gpu[2 * i]), got_d(gpu[2 * i + 1]);
            const double scale_o = std::max(1.0f, glm::length(cpu.origin));
            const double scale_d = std::max(1.0f, glm::length(cpu.dir));
            const double e = std::max(glm::length(got_o - cpu.origin) / scale_o,
                                      glm::length(got_d - cpu.dir) / scale_d) /
                             std::ldexp(1.0, -20);
            worst = std::max(worst, e);
            if (e > 1.0 && off++ < 5)
                ADD_FAILURE() << c.name << ": point (" << p.x << ", " << p.y << ") lens (" << p.z
                              << ", " << p.w << "): CPU origin " << cpu.origin.x << " "
                              << cpu.origin.y << " " << cpu.origin.z << " dir " << cpu.dir.x
                              << " " << cpu.dir.y << " " << cpu.dir.z << ", GPU origin "
                              << got_o.x << " " << got_o.y << " " << got_o.z << " dir "
                              << got_d.x << " " << got_d.y << " " << got_d.z;
        }
        std::printf("[ camera ray] %-38s %zu points: worst difference %.3g of the bound\n",
                    c.name.c_str(), points.size(), worst);
        EXPECT_EQ(off, 0) << c.name;
    }
}

TEST(CameraRay, SampleDiscStaysOnTheUnitDisc) {
    // The concentric map's corners and centre land where Shirley and Chiu put them.
    EXPECT_EQ(sample_disc(0.5f, 0.5f), glm::vec2(0.0f));
    EXPECT_NEAR(sample_disc(1.0f, 0.5f).x, 1.0f, 1e-7f);
    EXPECT_NEAR(sample_disc(0.5f, 1.0f).y, 1.0f, 1e-7f);
    EXPECT_NEAR(glm::length(sample_disc(1.0f, 1.0f)), 1.0f, 1e-6f);
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int i = 0; i < 10000; ++i) EXPECT_LE(glm::length(sample_disc(u(rng), u(rng))), 1.0f + 1e-6f);
}

}  // namespace
}  // namespace glslppm
