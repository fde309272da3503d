// GLSL 4.30 compute programs: locating the shader folder, resolving #include, compiling with
// errors that name the file and line, and a per-context cache of specialized programs.
#pragma once

#include <epoxy/gl.h>

#include <array>
#include <filesystem>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace glslppm::gl {

// A shader that failed to load, compile or link; the message names the program, the file
// (relative to the shader folder) and the line, followed by the driver's message.
class ShaderError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// `#define NAME VALUE` lines that specialize a program, in order.
using Defines = std::vector<std::pair<std::string, std::string>>;

// The shader folder: $GLSLPPM_SHADER_DIR if set; else `shaders/` beside the binary or shared
// object holding this code, or in its parent or grandparent folder; else the source tree's
// (GLSLPPM_SOURCE_SHADER_DIR) if it exists. Never the current directory. A candidate counts
// only if it holds common/rng.glsl. Throws ShaderError naming the places searched.
std::filesystem::path shader_dir();

// A stage file with its includes spliced in. `#include "common/x.glsl"` paths are relative
// to the shader folder; each file is included once. `#line N I` directives keep compiler
// messages pointing at the right place: I indexes `files` (0 is the stage file).
struct ResolvedSource {
    std::string text;
    std::vector<std::string> files;
};
ResolvedSource resolve_includes(const std::filesystem::path& root, const std::string& stage_file);

// The full source as compiled: `#version 430 core`, the defines, then the resolved source.
std::string assemble_source(const ResolvedSource& resolved, const Defines& defines);

// Rewrites a driver's info log ("0:12(3): error: ..." from Mesa, "0(12) : error C0000: ..."
// from NVIDIA) as "program: file:line: error: ..." lines.
std::string format_shader_log(const std::string& program, const std::string& log,
                              const std::vector<std::string>& files);

class ComputeProgram {
  public:
    // Compiles and links `stage_file` (e.g. "eye_trace.comp") from shader_dir(), or from
    // `root`, with the defines. Needs a current GL 4.3 context. Throws ShaderError.
    ComputeProgram(const std::string& stage_file, const Defines& defines);
    ComputeProgram(const std::filesystem::path& root, const std::string& stage_file,
                   const Defines& defines);
    ~ComputeProgram();
    ComputeProgram(const ComputeProgram&) = delete;
    ComputeProgram& operator=(const ComputeProgram&) = delete;
    ComputeProgram(ComputeProgram&& other) noexcept;
    ComputeProgram& operator=(ComputeProgram&& other) noexcept;

    GLuint id() const { return id_; }
    void use() const { glUseProgram(id_); }
    // The uniform's location (cached); -1 when the program has no such active uniform.
    GLint uniform(const char* name) const;
    // layout(local_size_x, _y, _z) as linked.
    std::array<GLint, 3> local_size() const { return local_size_; }
    const std::string& name() const { return name_; }
    // True when it was loaded from a binary kept by an earlier context (program_binaries.h)
    // rather than compiled.
    bool reused() const { return reused_; }
    // Included files, by #line index (0 is the stage file).
    const std::vector<std::string>& files() const { return files_; }

  private:
    void build(const std::filesystem::path& root, const Defines& defines);

    GLuint id_ = 0;
    std::string name_;
    std::vector<std::string> files_;
    std::array<GLint, 3> local_size_{0, 0, 0};
    bool reused_ = false;
    mutable std::unordered_map<std::string, GLint> uniforms_;
};

// Compiled programs of one context, keyed by (stage file, defines). Lives in EglContext and
// is destroyed while its context is current.
class ProgramCache {
  public:
    const ComputeProgram& get(const std::string& stage_file, const Defines& defines);
    std::size_t size() const { return programs_.size(); }
    void clear() { programs_.clear(); }

  private:
    std::map<std::string, std::unique_ptr<ComputeProgram>> programs_;
};

}  // namespace glslppm::gl
