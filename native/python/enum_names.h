// The names Python uses for the scene's enums, one table each, in the enums' order
// (native/scene/scene.h): the constructors parse them, scene_contents writes them.
#pragma once

#include <pybind11/pybind11.h>

#include <cstddef>
#include <iterator>
#include <string>

#include "scene/scene.h"

namespace glslppm {

inline constexpr const char* kMaterialKinds[] = {"diffuse",     "conductor",   "dielectric",
                                                 "plastic",     "translucent", "transparent",
                                                 "mix"};
inline constexpr const char* kTextureChannels[] = {"red", "green", "blue", "alpha", "luminance"};
inline constexpr const char* kMixModes[] = {"constant", "fresnel", "facing", "layer_fresnel"};
inline constexpr const char* kTextureWraps[] = {"repeat", "clip", "extend", "mirror"};
inline constexpr const char* kTextureInterpolations[] = {"linear", "closest"};
inline constexpr const char* kLightKinds[] = {"point", "spot", "sun", "area"};
inline constexpr const char* kAreaShapes[] = {"square", "rectangle", "disk", "ellipse"};
inline constexpr const char* kProjections[] = {"perspective", "orthographic"};

static_assert(std::size(kMaterialKinds) == std::size_t(MaterialKind::Mix) + 1);
static_assert(std::size(kTextureChannels) == std::size_t(TextureChannel::Luminance) + 1);
static_assert(std::size(kMixModes) == std::size_t(MixFactor::LayerFresnel) + 1);
static_assert(std::size(kTextureWraps) == std::size_t(TextureWrap::Mirror) + 1);
static_assert(std::size(kTextureInterpolations) ==
              std::size_t(TextureInterpolation::Closest) + 1);
static_assert(std::size(kLightKinds) == std::size_t(LightKind::Area) + 1);
static_assert(std::size(kAreaShapes) == std::size_t(AreaShape::Ellipse) + 1);
static_assert(std::size(kProjections) == std::size_t(Projection::Orthographic) + 1);

// The enum named `value`; ValueError listing the names otherwise ("Light kind: 'x' is not
// one of point, spot, sun, area").
template <typename Enum, std::size_t N>
Enum parse_name(const std::string& value, const char* const (&names)[N], const char* what) {
    for (std::size_t k = 0; k < N; ++k)
        if (value == names[k]) return static_cast<Enum>(k);
    std::string list;
    for (const char* n : names) list += (list.empty() ? "" : ", ") + std::string(n);
    throw pybind11::value_error(std::string(what) + ": '" + value + "' is not one of " + list);
}

template <typename Enum, std::size_t N>
const char* name_of(Enum value, const char* const (&names)[N]) {
    const auto k = static_cast<std::size_t>(value);
    return k < N ? names[k] : "?";
}

}  // namespace glslppm
