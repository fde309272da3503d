#include "gl/shader_program.h"

#include "gl/object_counts.h"
#include "gl/program_binaries.h"

#include <dlfcn.h>

#include <cstdlib>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <system_error>

namespace glslppm::gl {
namespace fs = std::filesystem;
namespace {

// A file every complete shader folder holds; a folder without it is not ours.
constexpr const char* kShaderMarker = "common/rng.glsl";

bool is_shader_dir(const fs::path& dir) {
    std::error_code ec;
    return fs::is_regular_file(dir / kShaderMarker, ec);
}

// The binary or shared object that contains this function, as an absolute path.
fs::path this_module_path() {
    Dl_info info{};
    if (dladdr(reinterpret_cast<void*>(&this_module_path), &info) != 0 &&
        info.dli_fname != nullptr) {
        const fs::path p = info.dli_fname;
        // glibc reports the main executable as argv[0], which may be relative to a directory
        // we have since left; /proc/self/exe is the executable's real path.
        if (p.is_absolute()) {
            std::error_code ec;
            const fs::path canonical = fs::weakly_canonical(p, ec);
            return ec ? p : canonical;
        }
    }
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    return ec ? fs::path() : exe;
}

std::string read_text(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return {};
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

struct IncludeResolver {
    fs::path root;
    std::vector<std::string> files;
    std::set<std::string> included;

    // Appends `relative` with its includes spliced in; `index` is its #line file number.
    void append(const std::string& relative, std::string& out) {
        const int index = static_cast<int>(files.size());
        files.push_back(relative);
        included.insert(relative);
        const fs::path path = root / relative;
        std::error_code ec;
        if (!fs::is_regular_file(path, ec)) {
            throw ShaderError(files.front() + ": cannot open shader file " + relative +
                              " (looked in " + root.string() + ")");
        }
        static const std::regex include_re(R"re(^\s*#\s*include\s+"([^"]+)"\s*$)re");
        static const std::regex version_re(R"(^\s*#\s*version\b.*$)");
        std::istringstream lines(read_text(path));
        int line_number = 0;
        for (std::string line; std::getline(lines, line);) {
            ++line_number;
            if (!line.empty() && line.back() == '\r') line.pop_back();
            std::smatch m;
            if (std::regex_match(line, m, include_re)) {
                const std::string target = m[1].str();
                if (included.count(target) == 0) {
                    if (!fs::is_regular_file(root / target, ec)) {
                        throw ShaderError(files.front() + ": " + relative + ":" +
                                          std::to_string(line_number) +
                                          ": cannot open include file \"" + target + "\"");
                    }
                    out += "#line 1 " + std::to_string(files.size()) + "\n";
                    append(target, out);
                    out += "#line " + std::to_string(line_number + 1) + " " +
                           std::to_string(index) + "\n";
                } else {
                    out += "\n";  // already included: an empty line keeps the numbering
                }
            } else if (std::regex_match(line, version_re)) {
                out += "\n";  // assemble_source writes the one #version line
            } else {
                out += line;
                out += '\n';
            }
        }
    }
};

bool is_identifier(const std::string& s) {
    static const std::regex id_re(R"([A-Za-z_][A-Za-z0-9_]*)");
    return std::regex_match(s, id_re);
}

std::string info_log(GLuint object, bool is_program) {
    GLint length = 0;
    if (is_program) {
        glGetProgramiv(object, GL_INFO_LOG_LENGTH, &length);
    } else {
        glGetShaderiv(object, GL_INFO_LOG_LENGTH, &length);
    }
    std::string log(static_cast<std::size_t>(length > 0 ? length : 1), '\0');
    if (is_program) {
        glGetProgramInfoLog(object, length, nullptr, log.data());
    } else {
        glGetShaderInfoLog(object, length, nullptr, log.data());
    }
    while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
    return log;
}

}  // namespace

fs::path shader_dir() {
    if (const char* env = std::getenv("GLSLPPM_SHADER_DIR"); env != nullptr && *env != 0) {
        const fs::path dir = env;
        if (!is_shader_dir(dir)) {
            throw ShaderError(std::string("GLSLPPM_SHADER_DIR=") + env + " holds no " +
                              kShaderMarker + ": point it at glslppm's shaders/ folder");
        }
        return dir;
    }
    std::vector<fs::path> searched;
    const fs::path module = this_module_path();
    if (!module.empty()) {
        fs::path dir = module.parent_path();
        for (int up = 0; up <= 2 && !dir.empty(); ++up) {
            searched.push_back(dir / "shaders");
            if (is_shader_dir(searched.back())) return searched.back();
            if (dir == dir.parent_path()) break;
            dir = dir.parent_path();
        }
    }
#ifdef GLSLPPM_SOURCE_SHADER_DIR
    searched.push_back(GLSLPPM_SOURCE_SHADER_DIR);
    if (is_shader_dir(searched.back())) return searched.back();
#endif
    std::string where;
    for (const fs::path& p : searched) where += (where.empty() ? "" : ", ") + p.string();
    throw ShaderError("glslppm's shaders/ folder was not found (searched " + where +
                      "): reinstall glslppm, or set GLSLPPM_SHADER_DIR to it");
}

ResolvedSource resolve_includes(const fs::path& root, const std::string& stage_file) {
    IncludeResolver resolver{root, {}, {}};
    std::string text = "#line 1 0\n";
    resolver.append(stage_file, text);
    return ResolvedSource{std::move(text), std::move(resolver.files)};
}

std::string assemble_source(const ResolvedSource& resolved, const Defines& defines) {
    std::string source = "#version 430 core\n";
    for (const auto& [name, value] : defines) {
        if (!is_identifier(name) || value.find('\n') != std::string::npos) {
            throw ShaderError(resolved.files.front() + ": bad define \"" + name + "\" = \"" +
                              value + "\"");
        }
        source += "#define " + name + (value.empty() ? "" : " " + value) + "\n";
    }
    return source + resolved.text;
}

std::string format_shader_log(const std::string& program, const std::string& log,
                              const std::vector<std::string>& files) {
    // Mesa: "0:12(3): error: ..."; NVIDIA: "0(12) : error C0000: ...";
    // AMD and others: "ERROR: 0:12: ...". The first number is the #line file index.
    static const std::regex mesa_re(R"(^\s*(\d+):(\d+)\(\d+\):\s*(.*)$)");
    static const std::regex nvidia_re(R"(^\s*(\d+)\((\d+)\)\s*:\s*(.*)$)");
    static const std::regex amd_re(R"(^\s*(ERROR|WARNING):\s*(\d+):(\d+):\s*(.*)$)");
    auto file_name = [&files](const std::string& index) {
        const unsigned long i = std::stoul(index);
        return i < files.size() ? files[i] : "source " + index;
    };
    std::string out;
    std::istringstream lines(log);
    for (std::string line; std::getline(lines, line);) {
        if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
        std::smatch m;
        std::string mapped;
        if (std::regex_match(line, m, mesa_re) || std::regex_match(line, m, nvidia_re)) {
            mapped = file_name(m[1].str()) + ":" + m[2].str() + ": " + m[3].str();
        } else if (std::regex_match(line, m, amd_re)) {
            std::string kind = m[1].str() == "ERROR" ? "error: " : "warning: ";
            mapped = file_name(m[2].str()) + ":" + m[3].str() + ": " + kind + m[4].str();
        } else {
            mapped = line;
        }
        if (!out.empty()) out += '\n';
        out += program + ": " + mapped;
    }
    return out;
}

ComputeProgram::ComputeProgram(const std::string& stage_file, const Defines& defines)
    : ComputeProgram(shader_dir(), stage_file, defines) {}

ComputeProgram::ComputeProgram(const fs::path& root, const std::string& stage_file,
                               const Defines& defines)
    : name_(stage_file) {
    build(root, defines);
}

void ComputeProgram::build(const fs::path& root, const Defines& defines) {
    const ResolvedSource resolved = resolve_includes(root, name_);
    files_ = resolved.files;
    const std::string source = assemble_source(resolved, defines);
    const std::string key = std::string(reinterpret_cast<const char*>(glGetString(GL_RENDERER))) +
                             '\n' + reinterpret_cast<const char*>(glGetString(GL_VERSION)) +
                             '\n' + source;
    id_ = glCreateProgram();
    if (load_program_binary(id_, key)) {
        reused_ = true;
        count_gl_objects(GlObject::Program, 1);
        glGetProgramiv(id_, GL_COMPUTE_WORK_GROUP_SIZE, local_size_.data());
        return;
    }
    glDeleteProgram(id_);
    id_ = 0;
    count_compiled_program();

    const GLuint shader = glCreateShader(GL_COMPUTE_SHADER);
    const char* text = source.c_str();
    glShaderSource(shader, 1, &text, nullptr);
    glCompileShader(shader);
    GLint ok = GL_FALSE;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (ok != GL_TRUE) {
        const std::string log = info_log(shader, false);
        glDeleteShader(shader);
        throw ShaderError(format_shader_log(name_, log, files_));
    }
    id_ = glCreateProgram();
    glProgramParameteri(id_, GL_PROGRAM_BINARY_RETRIEVABLE_HINT, GL_TRUE);
    glAttachShader(id_, shader);
    glLinkProgram(id_);
    glDetachShader(id_, shader);
    glDeleteShader(shader);
    glGetProgramiv(id_, GL_LINK_STATUS, &ok);
    if (ok != GL_TRUE) {
        const std::string log = info_log(id_, true);
        glDeleteProgram(id_);
        id_ = 0;
        // Link logs carry no file:line; each line becomes "program: link error: message".
        std::string message;
        std::istringstream lines(log);
        for (std::string line; std::getline(lines, line);) {
            if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
            if (line.rfind("error: ", 0) == 0) line.erase(0, 7);
            message += (message.empty() ? "" : "\n") + name_ + ": link error: " + line;
        }
        throw ShaderError(message.empty() ? name_ + ": link error" : message);
    }
    glGetProgramiv(id_, GL_COMPUTE_WORK_GROUP_SIZE, local_size_.data());
    count_gl_objects(GlObject::Program, 1);
    keep_program_binary(id_, key);
}

ComputeProgram::~ComputeProgram() {
    if (id_ != 0) {
        glDeleteProgram(id_);
        count_gl_objects(GlObject::Program, -1);
    }
}

ComputeProgram::ComputeProgram(ComputeProgram&& other) noexcept
    : id_(std::exchange(other.id_, 0)),
      name_(std::move(other.name_)),
      files_(std::move(other.files_)),
      local_size_(other.local_size_),
      reused_(other.reused_),
      uniforms_(std::move(other.uniforms_)) {}

ComputeProgram& ComputeProgram::operator=(ComputeProgram&& other) noexcept {
    if (this != &other) {
        if (id_ != 0) {
            glDeleteProgram(id_);
            count_gl_objects(GlObject::Program, -1);
        }
        id_ = std::exchange(other.id_, 0);
        name_ = std::move(other.name_);
        files_ = std::move(other.files_);
        local_size_ = other.local_size_;
        reused_ = other.reused_;
        uniforms_ = std::move(other.uniforms_);
    }
    return *this;
}

GLint ComputeProgram::uniform(const char* name) const {
    auto it = uniforms_.find(name);
    if (it != uniforms_.end()) return it->second;
    const GLint location = glGetUniformLocation(id_, name);
    uniforms_.emplace(name, location);
    return location;
}

const ComputeProgram& ProgramCache::get(const std::string& stage_file, const Defines& defines) {
    std::string key = stage_file;
    for (const auto& [name, value] : defines) key += '\n' + name + '=' + value;
    auto it = programs_.find(key);
    if (it == programs_.end()) {
        it = programs_.emplace(key, std::make_unique<ComputeProgram>(stage_file, defines)).first;
    }
    return *it->second;
}

}  // namespace glslppm::gl
