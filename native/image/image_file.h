// Image files as textures: PNG and JPEG (8-bit, sRGB encoded), 16-bit PNG and Radiance .hdr
// (decoded to linear float), OpenEXR (linear float). Rows are stored bottom-first, as
// Scene's Texture expects (row 0 = v = 0).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>

#include "scene/scene.h"

namespace glslppm {

// An unreadable or undecodable image; the message names the file.
class ImageFileError : public std::runtime_error {
  public:
    using std::runtime_error::runtime_error;
};

// Largest image accepted (16384 x 8192, a 16k HDRI): a corrupt header claiming more is
// rejected before anything is allocated.
inline constexpr std::size_t kMaxTexels = std::size_t(1) << 27;

// Reads PNG, JPEG, .hdr (by content) or .exr (by extension). Throws ImageFileError.
Texture load_texture(const std::string& path);

// Decodes PNG, JPEG or .hdr bytes; `name` is used in messages and as the texture's name.
Texture decode_texture(std::span<const std::uint8_t> bytes, const std::string& name,
                       std::size_t max_texels = kMaxTexels);

// The sRGB transfer function, inverted (IEC 61966-2-1): encoded value in [0, 1] to linear.
float srgb_decode(float encoded);

}  // namespace glslppm
