#include "image/exr.h"

#include <stdexcept>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>

namespace glslppm {

void write_exr(const std::string& path, const FloatImage& image,
               const std::map<std::string, std::string>& attributes) {
    try {
        Imf::Header header(image.width, image.height);
        for (const char* c : {"R", "G", "B", "A"})
            header.channels().insert(c, Imf::Channel(Imf::FLOAT));
        for (const auto& [key, value] : attributes)
            header.insert("glslppm/" + key, Imf::StringAttribute(value));
        Imf::FrameBuffer frame;
        char* base = const_cast<char*>(reinterpret_cast<const char*>(image.rgba.data()));
        const std::size_t xs = 4 * sizeof(float), ys = xs * static_cast<std::size_t>(image.width);
        const char* names[4] = {"R", "G", "B", "A"};
        for (int c = 0; c < 4; ++c)
            frame.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
        Imf::OutputFile file(path.c_str(), header);
        file.setFrameBuffer(frame);
        file.writePixels(image.height);
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot write EXR file " + path + ": " + e.what());
    }
}

void write_multilayer_exr(const std::string& path, int width, int height,
                          const std::vector<ExrPass>& passes,
                          const std::map<std::string, std::string>& attributes,
                          const std::string& view_layer) {
    try {
        Imf::Header header(width, height);
        // Blender reads a file as layers and passes only with this attribute
        // (source/blender/imbuf/intern/openexr/openexr_api.cpp).
        header.insert("BlenderMultiChannel", Imf::StringAttribute("Blender V2.55.1 and newer"));
        for (const auto& [key, value] : attributes)
            header.insert("glslppm/" + key, Imf::StringAttribute(value));
        Imf::FrameBuffer frame;
        const std::size_t xs = 4 * sizeof(float), ys = xs * static_cast<std::size_t>(width);
        for (const ExrPass& pass : passes) {
            if (pass.rgba.size() != std::size_t(width) * height * 4 || pass.channels.size() > 4)
                throw std::invalid_argument("pass " + pass.name + " is not " +
                                            std::to_string(width) + "x" + std::to_string(height) +
                                            " x 4 floats with at most 4 channels");
            char* base = const_cast<char*>(reinterpret_cast<const char*>(pass.rgba.data()));
            for (std::size_t c = 0; c < pass.channels.size(); ++c) {
                const std::string name = view_layer + "." + pass.name + "." + pass.channels[c];
                header.channels().insert(name, Imf::Channel(Imf::FLOAT));
                frame.insert(name, Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
            }
        }
        Imf::OutputFile file(path.c_str(), header);
        file.setFrameBuffer(frame);
        file.writePixels(height);
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot write EXR file " + path + ": " + e.what());
    }
}

std::map<std::string, std::vector<float>> read_exr_channels(const std::string& path, int* width,
                                                            int* height) {
    try {
        Imf::InputFile file(path.c_str());
        const Imath::Box2i window = file.header().dataWindow();
        const int w = window.max.x - window.min.x + 1, h = window.max.y - window.min.y + 1;
        std::map<std::string, std::vector<float>> channels;
        Imf::FrameBuffer frame;
        for (auto it = file.header().channels().begin(); it != file.header().channels().end();
             ++it) {
            std::vector<float>& data = channels[it.name()];
            data.assign(std::size_t(w) * h, 0.0f);
            char* base = reinterpret_cast<char*>(data.data()) -
                         (static_cast<std::ptrdiff_t>(window.min.x) * sizeof(float) +
                          static_cast<std::ptrdiff_t>(window.min.y) * w * sizeof(float));
            frame.insert(it.name(), Imf::Slice(Imf::FLOAT, base, sizeof(float),
                                               sizeof(float) * static_cast<std::size_t>(w)));
        }
        file.setFrameBuffer(frame);
        file.readPixels(window.min.y, window.max.y);
        if (width) *width = w;
        if (height) *height = h;
        return channels;
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot read EXR file " + path + ": " + e.what());
    }
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
        if (attributes) {
            for (auto it = file.header().begin(); it != file.header().end(); ++it) {
                const std::string name = it.name();
                // Ours under "glslppm/"; the farm attributes ("glslppm.seed", ...) as they
                // are, also from files Blender wrote (the add-on's render metadata).
                const bool ours = name.rfind("glslppm/", 0) == 0;
                if (!ours && name.rfind("glslppm.", 0) != 0) continue;
                if (auto* s = dynamic_cast<const Imf::StringAttribute*>(&it.attribute()))
                    (*attributes)[ours ? name.substr(8) : name] = s->value();
            }
        }
        return image;
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot read EXR file " + path + ": " + e.what());
    }
}

}  // namespace glslppm
