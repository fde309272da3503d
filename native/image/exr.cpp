#include "image/exr.h"

#include <stdexcept>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

namespace glslppm {

namespace {

// Blender reads a file as layers and passes only with this attribute
// (source/blender/imbuf/intern/openexr/openexr_api.cpp).
const char* kBlenderMultiChannel = "BlenderMultiChannel";

// Ours (written under "glslppm/", returned without it) and the farm attributes "glslppm.*"
// as they are, also from files Blender wrote (the add-on's render metadata).
std::map<std::string, std::string> read_attributes(const Imf::Header& header) {
    std::map<std::string, std::string> attributes;
    for (auto it = header.begin(); it != header.end(); ++it) {
        const std::string name = it.name();
        const bool ours = name.rfind("glslppm/", 0) == 0;
        if (!ours && name.rfind("glslppm.", 0) != 0) continue;
        if (auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
            attributes[ours ? name.substr(8) : name] = s->value();
    }
    return attributes;
}

// One channel of interleaved height x width x 4 floats, as a plane of height x width.
std::vector<float> channel_plane(const std::vector<float>& rgba, std::size_t channel) {
    std::vector<float> plane(rgba.size() / 4);
    for (std::size_t i = 0; i < plane.size(); ++i) plane[i] = rgba[4 * i + channel];
    return plane;
}

}  // namespace

void write_exr_file(const std::string& path, const ExrChannels& file) {
    try {
        Imf::Header header(file.width, file.height);
        if (file.multilayer)
            header.insert(kBlenderMultiChannel, Imf::StringAttribute("Blender V2.55.1 and newer"));
        for (const auto& [key, value] : file.attributes)
            header.insert("glslppm/" + key, Imf::StringAttribute(value));
        Imf::FrameBuffer frame;
        const std::size_t pixels = std::size_t(file.width) * file.height;
        for (const auto& [name, plane] : file.channels) {
            if (plane.size() != pixels)
                throw std::invalid_argument(
                    "channel " + name + " has " + std::to_string(plane.size()) + " values, not " +
                    std::to_string(file.width) + "x" + std::to_string(file.height));
            header.channels().insert(name, Imf::Channel(Imf::FLOAT));
            char* base = const_cast<char*>(reinterpret_cast<const char*>(plane.data()));
            frame.insert(name, Imf::Slice(Imf::FLOAT, base, sizeof(float),
                                          sizeof(float) * static_cast<std::size_t>(file.width)));
        }
        Imf::OutputFile out(path.c_str(), header);
        out.setFrameBuffer(frame);
        out.writePixels(file.height);
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot write EXR file " + path + ": " + e.what());
    }
}

void write_exr(const std::string& path, const FloatImage& image,
               const std::map<std::string, std::string>& attributes) {
    ExrChannels file{image.width, image.height, {}, attributes, false};
    const char* names[4] = {"R", "G", "B", "A"};
    for (std::size_t c = 0; c < 4; ++c) file.channels[names[c]] = channel_plane(image.rgba, c);
    write_exr_file(path, file);
}

void write_multilayer_exr(const std::string& path, int width, int height,
                          const std::vector<ExrPass>& passes,
                          const std::map<std::string, std::string>& attributes,
                          const std::string& view_layer) {
    ExrChannels file{width, height, {}, attributes, true};
    for (const ExrPass& pass : passes) {
        if (pass.rgba.size() != std::size_t(width) * height * 4 || pass.channels.size() > 4)
            throw std::runtime_error("cannot write EXR file " + path + ": pass " + pass.name +
                                     " is not " + std::to_string(width) + "x" +
                                     std::to_string(height) +
                                     " x 4 floats with at most 4 channels");
        for (std::size_t c = 0; c < pass.channels.size(); ++c)
            file.channels[view_layer + "." + pass.name + "." + pass.channels[c]] =
                channel_plane(pass.rgba, c);
    }
    write_exr_file(path, file);
}

ExrChannels read_exr_file(const std::string& path) {
    try {
        Imf::InputFile in(path.c_str());
        const Imath::Box2i window = in.header().dataWindow();
        ExrChannels file;
        file.width = window.max.x - window.min.x + 1;
        file.height = window.max.y - window.min.y + 1;
        file.attributes = read_attributes(in.header());
        file.multilayer = in.header().find(kBlenderMultiChannel) != in.header().end();
        Imf::FrameBuffer frame;
        const std::size_t w = static_cast<std::size_t>(file.width);
        for (auto it = in.header().channels().begin(); it != in.header().channels().end(); ++it) {
            std::vector<float>& data = file.channels[it.name()];
            data.assign(w * file.height, 0.0f);
            char* base = reinterpret_cast<char*>(data.data()) -
                         (static_cast<std::ptrdiff_t>(window.min.x) * sizeof(float) +
                          static_cast<std::ptrdiff_t>(window.min.y) * w * sizeof(float));
            frame.insert(it.name(), Imf::Slice(Imf::FLOAT, base, sizeof(float), sizeof(float) * w));
        }
        in.setFrameBuffer(frame);
        in.readPixels(window.min.y, window.max.y);
        return file;
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot read EXR file " + path + ": " + e.what());
    }
}

std::map<std::string, std::vector<float>> read_exr_channels(const std::string& path, int* width,
                                                            int* height) {
    ExrChannels file = read_exr_file(path);
    if (width) *width = file.width;
    if (height) *height = file.height;
    return std::move(file.channels);
}

FloatImage read_exr(const std::string& path, std::map<std::string, std::string>* attributes) {
    try {
        Imf::InputFile file(path.c_str());
        const Imath::Box2i window = file.header().dataWindow();
        FloatImage image;
        image.width = window.max.x - window.min.x + 1;
        image.height = window.max.y - window.min.y + 1;
        image.rgba.assign(std::size_t(image.width) * image.height * 4, 0.0f);
        Imf::FrameBuffer frame;
        const std::size_t xs = 4 * sizeof(float), ys = xs * static_cast<std::size_t>(image.width);
        char* base = reinterpret_cast<char*>(image.rgba.data()) -
                     (static_cast<std::ptrdiff_t>(window.min.x) * xs +
                      static_cast<std::ptrdiff_t>(window.min.y) * ys);
        const char* names[4] = {"R", "G", "B", "A"};
        for (int c = 0; c < 4; ++c)
            frame.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys, 1, 1,
                                              c == 3 ? 1.0 : 0.0));
        file.setFrameBuffer(frame);
        file.readPixels(window.min.y, window.max.y);
        if (attributes) *attributes = read_attributes(file.header());
        return image;
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot read EXR file " + path + ": " + e.what());
    }
}

}  // namespace glslppm
