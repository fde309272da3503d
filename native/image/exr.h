// Float RGBA OpenEXR files, with the render's statistics and settings in the header.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace glslppm {

struct FloatImage {
    int width = 0, height = 0;
    std::vector<float> rgba;  // height x width x 4, row 0 at the top
};

// Writes 32-bit float R, G, B, A channels; `attributes` become string attributes of the
// header (passes, photons emitted, seconds, settings). Throws std::runtime_error naming
// the file on failure.
void write_exr(const std::string& path, const FloatImage& image,
               const std::map<std::string, std::string>& attributes = {});

// Reads R, G, B, A (A = 1 where missing) and the header's string attributes: ours (written
// under "glslppm/", returned without it) and the farm attributes "glslppm.*" as they are.
FloatImage read_exr(const std::string& path, std::map<std::string, std::string>* attributes = nullptr);

}  // namespace glslppm
