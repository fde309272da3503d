#include "image/exr.h"

#include <stdexcept>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfInputPart.h>
#include <ImfMultiPartInputFile.h>
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

namespace {

// A channel's full name in a multi-part file. Blender 5.x writes one part per pass, named
// "<view layer>.<pass>", whose channels keep their full names; a file written by other tools
// may name the channels of a part "R", "G", "B" only: those get the part's name in front, so
// that no two parts' channels share a name.
std::string part_channel_name(const Imf::Header& header, int parts, const std::string& channel) {
    if (parts < 2 || !header.hasName()) return channel;
    const std::string& part = header.name();
    if (channel.rfind(part + ".", 0) == 0) return channel;
    return part + "." + channel;
}

}  // namespace

ExrChannels read_exr_file(const std::string& path) {
    try {
        // Every part of the file (a single-part file is one part), each into its channels.
        Imf::MultiPartInputFile in(path.c_str());
        ExrChannels file;
        for (int p = 0; p < in.parts(); ++p) {
            Imf::InputPart part(in, p);
            const Imf::Header& header = part.header();
            const Imath::Box2i window = header.dataWindow();
            const int width = window.max.x - window.min.x + 1;
            const int height = window.max.y - window.min.y + 1;
            if (p == 0) {
                file.width = width;
                file.height = height;
            } else if (width != file.width || height != file.height) {
                throw std::runtime_error("part " + std::to_string(p) + " is " +
                                         std::to_string(width) + "x" + std::to_string(height) +
                                         ", part 0 " + std::to_string(file.width) + "x" +
                                         std::to_string(file.height));
            }
            for (const auto& [key, value] : read_attributes(header))
                file.attributes.emplace(key, value);
            file.multilayer = file.multilayer || header.find(kBlenderMultiChannel) != header.end();
            Imf::FrameBuffer frame;
            const std::size_t w = static_cast<std::size_t>(width);
            for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
                const std::string name = part_channel_name(header, in.parts(), it.name());
                if (file.channels.count(name))
                    throw std::runtime_error("channel " + name + " is in two parts");
                std::vector<float>& data = file.channels[name];
                data.assign(w * height, 0.0f);
                char* base = reinterpret_cast<char*>(data.data()) -
                             (static_cast<std::ptrdiff_t>(window.min.x) * sizeof(float) +
                              static_cast<std::ptrdiff_t>(window.min.y) * w * sizeof(float));
                frame.insert(it.name(),
                             Imf::Slice(Imf::FLOAT, base, sizeof(float), sizeof(float) * w));
            }
            part.setFrameBuffer(frame);
            part.readPixels(window.min.y, window.max.y);
        }
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
