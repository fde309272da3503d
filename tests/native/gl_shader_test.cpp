// ComputeProgram, the include resolver and shader_dir() on the real GL driver.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "gl/gl_thread.h"
#include "gl/shader_program.h"

namespace glslppm::gl {
namespace {
namespace fs = std::filesystem;

GlThread& gl() {
    static GlThread thread;
    return thread;
}

// A throwaway shader folder with the files a test writes.
class TempShaderDir {
  public:
    TempShaderDir() {
        std::string pattern = (fs::temp_directory_path() / "glslppm-shaders-XXXXXX").string();
        root_ = mkdtemp(pattern.data());
        fs::create_directories(root_ / "common");
    }
    ~TempShaderDir() { fs::remove_all(root_); }
    void write(const std::string& relative, const std::string& text) const {
        std::ofstream(root_ / relative) << text;
    }
    const fs::path& root() const { return root_; }

  private:
    fs::path root_;
};

std::string compile_error(const fs::path& root, const std::string& file, const Defines& d = {}) {
    return gl().call([&]() -> std::string {
        try {
            ComputeProgram program(root, file, d);
            return "";
        } catch (const ShaderError& e) {
            return e.what();
        }
    });
}

TEST(GlShader, ErrorInIncludedFileNamesProgramFileAndLine) {
    TempShaderDir dir;
    dir.write("common/helpers.glsl",
              "// helpers\n"
              "float twice(float x) { return 2.0 * x; }\n"
              "\n"
              "float broken(float x) { return x +* 2.0; }\n");
    dir.write("stage.comp",
              "#include \"common/helpers.glsl\"\n"
              "layout(local_size_x = 1) in;\n"
              "void main() {}\n");
    const std::string message = compile_error(dir.root(), "stage.comp");
    EXPECT_NE(message.find("stage.comp: common/helpers.glsl:4: "), std::string::npos) << message;
    EXPECT_NE(message.find("error"), std::string::npos) << message;
}

TEST(GlShader, ErrorAfterAnIncludeMapsBackToTheStageFile) {
    TempShaderDir dir;
    dir.write("common/a.glsl", "float a() { return 1.0; }\nfloat a2() { return 2.0; }\n");
    dir.write("stage.comp",
              "#include \"common/a.glsl\"\n"
              "#include \"common/a.glsl\"\n"  // included once only
              "layout(local_size_x = 1) in;\n"
              "void main() {\n"
              "  float x = undefined_name;\n"
              "}\n");
    const std::string message = compile_error(dir.root(), "stage.comp");
    EXPECT_NE(message.find("stage.comp: stage.comp:5: "), std::string::npos) << message;
    EXPECT_NE(message.find("undefined_name"), std::string::npos) << message;
}

TEST(GlShader, LinkErrorIsReported) {
    TempShaderDir dir;
    // A compute shader without a work group size compiles but cannot link.
    dir.write("nosize.comp", "void main() {}\n");
    const std::string message = compile_error(dir.root(), "nosize.comp");
    EXPECT_NE(message.find("nosize.comp: link error"), std::string::npos) << message;
}

TEST(GlShader, MissingIncludeNamesTheLine) {
    TempShaderDir dir;
    dir.write("stage.comp", "\n\n#include \"common/nothere.glsl\"\n");
    const std::string message = compile_error(dir.root(), "stage.comp");
    EXPECT_NE(message.find("stage.comp: stage.comp:3: cannot open include file"), std::string::npos)
        << message;
}

TEST(GlShader, DefinesSpecializeAndLocalSizeIsQueried) {
    TempShaderDir dir;
    dir.write("sized.comp",
              "layout(local_size_x = SIZE_X, local_size_y = 2) in;\n"
              "uniform uint u_scale;\n"
              "layout(std430, binding = 0) buffer B { uint b[]; };\n"
              "void main() { b[gl_LocalInvocationIndex] = u_scale; }\n");
    const auto [size, location, files] = gl().call([&] {
        ComputeProgram program(dir.root(), "sized.comp", {{"SIZE_X", "8"}});
        ComputeProgram moved = std::move(program);
        EXPECT_EQ(program.id(), 0u);
        return std::tuple{moved.local_size(), moved.uniform("u_scale"), moved.files()};
    });
    EXPECT_EQ(size, (std::array<GLint, 3>{8, 2, 1}));
    EXPECT_GE(location, 0);
    EXPECT_EQ(files, std::vector<std::string>{"sized.comp"});
}

TEST(GlShader, NvidiaAndMesaLogsMapToFiles) {
    const std::vector<std::string> files = {"eye_trace.comp", "common/rng.glsl"};
    EXPECT_EQ(format_shader_log("eye_trace.comp",
                                "1(12) : error C0000: syntax error, unexpected '*'", files),
              "eye_trace.comp: common/rng.glsl:12: error C0000: syntax error, unexpected '*'");
    EXPECT_EQ(
        format_shader_log("eye_trace.comp", "1:12(3): error: syntax error, unexpected '*'", files),
        "eye_trace.comp: common/rng.glsl:12: error: syntax error, unexpected '*'");
    EXPECT_EQ(format_shader_log("eye_trace.comp", "ERROR: 0:7: 'x' : undeclared identifier", files),
              "eye_trace.comp: eye_trace.comp:7: error: 'x' : undeclared identifier");
}

TEST(GlShader, ProgramCacheCompilesOncePerKey) {
    const auto [same, different, size] = gl().call([] {
        ProgramCache& cache = gl().context().programs();
        cache.clear();
        const ComputeProgram& a = cache.get("tests/rng_stream.comp", {{"RNG_PCG", ""}});
        const ComputeProgram& b = cache.get("tests/rng_stream.comp", {{"RNG_PCG", ""}});
        const ComputeProgram& c = cache.get("tests/rng_stream.comp", {{"RNG_PAPER", ""}});
        return std::tuple{&a == &b, &a != &c, cache.size()};
    });
    EXPECT_TRUE(same);
    EXPECT_TRUE(different);
    EXPECT_EQ(size, 2u);
}

TEST(GlShader, RngIncludeRejectsNoOrBothGenerators) {
    const fs::path root = shader_dir();
    const std::string none = compile_error(root, "tests/rng_stream.comp");
    EXPECT_NE(none.find("common/rng.glsl:"), std::string::npos) << none;
    EXPECT_NE(none.find("define exactly one of RNG_PAPER and RNG_PCG"), std::string::npos) << none;
    const std::string both =
        compile_error(root, "tests/rng_stream.comp", {{"RNG_PAPER", ""}, {"RNG_PCG", ""}});
    EXPECT_NE(both.find("not both"), std::string::npos) << both;
}

TEST(GlShader, ShaderDirDoesNotDependOnTheCurrentDirectory) {
    const char* env = std::getenv("GLSLPPM_SHADER_DIR");
    if (env != nullptr) GTEST_SKIP() << "GLSLPPM_SHADER_DIR is set";
    const fs::path here = fs::current_path();
    const fs::path found = shader_dir();
    fs::current_path("/");
    const fs::path from_root = shader_dir();
    fs::current_path(here);
    EXPECT_EQ(found, from_root);
    EXPECT_TRUE(found.is_absolute()) << found;
    EXPECT_TRUE(fs::exists(from_root / "common/rng.glsl"));
    EXPECT_TRUE(fs::exists(from_root / "tests/rng_stream.comp"));
}

TEST(GlShader, ShaderDirEnvironmentOverrides) {
    TempShaderDir dir;
    dir.write("common/rng.glsl", "// marker\n");
    const char* old = std::getenv("GLSLPPM_SHADER_DIR");
    const std::string saved = old != nullptr ? old : "";
    setenv("GLSLPPM_SHADER_DIR", dir.root().c_str(), 1);
    const fs::path found = shader_dir();
    setenv("GLSLPPM_SHADER_DIR", "/nonexistent", 1);
    EXPECT_THROW(shader_dir(), ShaderError);
    old != nullptr ? (void)setenv("GLSLPPM_SHADER_DIR", saved.c_str(), 1)
                   : (void)unsetenv("GLSLPPM_SHADER_DIR");
    EXPECT_EQ(found, dir.root());
}

}  // namespace
}  // namespace glslppm::gl
