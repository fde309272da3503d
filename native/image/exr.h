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

// One pass of a multi-layer file: Blender's pass name ("Combined", "Depth", ...), its channel
// letters ("RGBA", "Z", "XYZ", "RGB"), and its pixels as height x width x 4 floats of which
// the first channels.size() are written.
struct ExrPass {
    std::string name;
    std::string channels;
    std::vector<float> rgba;
};

// A multi-layer EXR as Blender writes one (and reads it into the compositor's Image node):
// channels "<view layer>.<pass>.<channel>", 32-bit float, with Blender's BlenderMultiChannel
// header attribute; `attributes` as write_exr's.
void write_multilayer_exr(const std::string& path, int width, int height,
                          const std::vector<ExrPass>& passes,
                          const std::map<std::string, std::string>& attributes = {},
                          const std::string& view_layer = "ViewLayer");

// Every channel of a file (of every part) by its full name, each height x width floats.
std::map<std::string, std::vector<float>> read_exr_channels(const std::string& path, int* width,
                                                            int* height);

// A file as it is, for tools that pass every layer through (glslppm-merge): each channel by
// its full name ("R" of a single-layer file, "ViewLayer.Depth.Z" of a multi-layer one).
struct ExrChannels {
    int width = 0, height = 0;
    std::map<std::string, std::vector<float>> channels;  // each height x width floats
    std::map<std::string, std::string> attributes;       // as read_exr returns them
    bool multilayer = false;  // Blender's BlenderMultiChannel header: it opens layers and passes
};

// Reads every part of the file (Blender 5.x writes a multi-layer EXR as one part per pass,
// named "<view layer>.<pass>"; a channel named only "R" in such a part is returned as
// "<part>.R"), with the attributes of all parts. Throws std::runtime_error naming the file on
// failure, also when the parts differ in size or two parts hold the same channel.
ExrChannels read_exr_file(const std::string& path);
// 32-bit float channels; attributes as write_exr writes them.
void write_exr_file(const std::string& path, const ExrChannels& file);

// Reads R, G, B, A (A = 1 where missing) and the header's string attributes: ours (written
// under "glslppm/", returned without it) and the farm attributes "glslppm.*" as they are.
FloatImage read_exr(const std::string& path, std::map<std::string, std::string>* attributes = nullptr);

}  // namespace glslppm
