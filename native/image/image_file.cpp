#include "image/image_file.h"

#include <stb/stb_image.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <memory>
#include <vector>

#include "image/exr.h"

namespace glslppm {
namespace {

struct StbFree {
    void operator()(void* p) const { stbi_image_free(p); }
};

std::string lower_extension(const std::string& path) {
    const auto dot = path.find_last_of('.');
    const auto slash = path.find_last_of('/');
    if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
    std::string ext = path.substr(dot + 1);
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

// stb_image returns rows top-first; Texture wants them bottom-first.
template <typename T>
std::vector<T> flip_rows(const T* top_first, int width, int height) {
    const std::size_t row = std::size_t(width) * 4;
    std::vector<T> out(row * std::size_t(height));
    for (int y = 0; y < height; ++y)
        std::memcpy(out.data() + std::size_t(height - 1 - y) * row,
                    top_first + std::size_t(y) * row, row * sizeof(T));
    return out;
}

std::string stb_reason() {
    const char* r = stbi_failure_reason();
    return r ? r : "unknown error";
}

Texture texture_from_exr(const std::string& path) {
    FloatImage image;
    try {
        image = read_exr(path);
    } catch (const std::exception& e) {
        throw ImageFileError(e.what());
    }
    if (image.width <= 0 || image.height <= 0)
        throw ImageFileError("image " + path + ": empty EXR image");
    if (std::size_t(image.width) * std::size_t(image.height) > kMaxTexels)
        throw ImageFileError("image " + path + ": " + std::to_string(image.width) + " x " +
                             std::to_string(image.height) + " is larger than the limit of " +
                             std::to_string(kMaxTexels) + " texels");
    Texture t;
    t.name = path;
    t.width = image.width;
    t.height = image.height;
    t.linear = flip_rows(image.rgba.data(), image.width, image.height);  // EXR: row 0 at the top
    return t;
}

}  // namespace

float srgb_decode(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}

Texture decode_texture(std::span<const std::uint8_t> bytes, const std::string& name,
                       std::size_t max_texels) {
    if (bytes.empty()) throw ImageFileError("image " + name + ": the file is empty");
    if (bytes.size() > std::size_t(INT32_MAX))
        throw ImageFileError("image " + name + ": larger than 2 GiB");
    const auto* data = bytes.data();
    const int size = static_cast<int>(bytes.size());
    int w = 0, h = 0, channels = 0;
    // Read the header first, so that a corrupt size is refused before any allocation.
    if (!stbi_info_from_memory(data, size, &w, &h, &channels))
        throw ImageFileError("image " + name + ": not a PNG, JPEG or Radiance HDR image (" +
                             stb_reason() + ")");
    if (w <= 0 || h <= 0 || std::size_t(w) * std::size_t(h) > max_texels)
        throw ImageFileError("image " + name + ": " + std::to_string(w) + " x " +
                             std::to_string(h) + " is outside the limit of " +
                             std::to_string(max_texels) + " texels");
    Texture t;
    t.name = name;
    t.width = w;
    t.height = h;
    if (stbi_is_hdr_from_memory(data, size)) {
        std::unique_ptr<float, StbFree> px(
            stbi_loadf_from_memory(data, size, &w, &h, &channels, 4));
        if (!px) throw ImageFileError("image " + name + ": cannot decode: " + stb_reason());
        t.linear = flip_rows(px.get(), w, h);
    } else if (stbi_is_16_bit_from_memory(data, size)) {
        // 16-bit PNG: sRGB encoded like 8-bit ones, but decoded to float to keep the precision.
        std::unique_ptr<std::uint16_t, StbFree> px(
            stbi_load_16_from_memory(data, size, &w, &h, &channels, 4));
        if (!px) throw ImageFileError("image " + name + ": cannot decode: " + stb_reason());
        std::vector<std::uint16_t> rows = flip_rows(px.get(), w, h);
        t.linear.resize(rows.size());
        for (std::size_t i = 0; i < rows.size(); ++i) {
            const float v = rows[i] / 65535.0f;
            t.linear[i] = (i % 4 == 3) ? v : srgb_decode(v);  // alpha is linear
        }
    } else {
        std::unique_ptr<stbi_uc, StbFree> px(
            stbi_load_from_memory(data, size, &w, &h, &channels, 4));
        if (!px) throw ImageFileError("image " + name + ": cannot decode: " + stb_reason());
        t.srgb8 = flip_rows(px.get(), w, h);
    }
    return t;
}

Texture load_texture(const std::string& path) {
    if (lower_extension(path) == "exr") return texture_from_exr(path);
    std::ifstream file(path, std::ios::binary);
    if (!file)
        throw ImageFileError("image " + path + ": cannot open the file (" + std::strerror(errno) +
                             ")");
    std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(file)),
                                    std::istreambuf_iterator<char>());
    if (file.bad()) throw ImageFileError("image " + path + ": read error");
    return decode_texture(bytes, path);
}

}  // namespace glslppm
