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
