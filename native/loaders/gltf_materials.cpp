#include "loaders/gltf_materials.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <limits>
#include <span>

#include "image/image_file.h"
#include "loaders/scene_file.h"

namespace glslppm::gltf {
namespace {

// Numbers in messages as written in files (0.3, not 0.300000).
std::string number_text(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
}

// Embedded images larger than this are refused (8192 x 8192): the renderer downscales
// anything above GL_MAX_TEXTURE_SIZE anyway, and a corrupt header must not allocate GiBs.
constexpr std::size_t kMaxEmbeddedTexels = std::size_t(1) << 26;

constexpr int kWrapRepeat = TINYGLTF_TEXTURE_WRAP_REPEAT;
constexpr int kWrapClamp = TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE;
constexpr int kWrapMirror = TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT;
constexpr int kFilterNearest = TINYGLTF_TEXTURE_FILTER_NEAREST;

struct Converter {
    const tinygltf::Model& model;
    DecodedImages& images;
    const std::string& base_dir;
    Scene& scene;
    std::vector<std::string>& warnings;
    std::map<int, int> scene_texture;  // glTF textures[] index -> Scene::textures index
    std::map<int, int> linear_copy;    // Scene::textures index -> its copy read as numbers

    void warn(const std::string& element, const std::string& what) {
        warnings.push_back(images.file + ": " + element + ": " + what);
    }
    [[noreturn]] void fail(const std::string& element, const std::string& what) const {
        throw SceneFileError(images.file + ": " + element + ": " + what);
    }

    bool image_texture(int index, const std::string& element, Texture& out);
    TextureWrap wrap_of(int sampler, const std::string& element);
    int texture(const tinygltf::TextureInfo& info, const std::string& element);
    int data_texture(const tinygltf::TextureInfo& info, const std::string& element);
    int mask_texture(int k, float alpha, float cutoff);
    int part(const Material& m);
    Material mix_of(int a, int b, float factor, int texture, TextureChannel channel);
    Material mix(const Material& a, const Material& b, float factor, int texture,
                 TextureChannel channel);
    glm::vec3 volume_absorption(const tinygltf::ExtensionMap& extensions,
                                const std::string& element);
    Material material(const tinygltf::Material& m, const std::string& element);
};

// URIs are percent-encoded (RFC 3986): "my%20wood.png" names "my wood.png".
std::string uri_decode(const std::string& uri) {
    std::string out;
    for (std::size_t i = 0; i < uri.size(); ++i) {
        const auto hex = [](char c) {
            return std::isxdigit(static_cast<unsigned char>(c))
                       ? std::stoi(std::string(1, c), nullptr, 16)
                       : -1;
        };
        if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) >= 0 && hex(uri[i + 2]) >= 0) {
            out += static_cast<char>(hex(uri[i + 1]) * 16 + hex(uri[i + 2]));
            i += 2;
        } else {
            out += uri[i];
        }
    }
    return out;
}

std::string image_name(const std::string& file, int index, const tinygltf::Image& image) {
    return file + ": images[" + std::to_string(index) + "]" +
           (image.name.empty() ? "" : " '" + image.name + "'");
}

std::string display_name(const std::string& element, const std::string& name) {
    return name.empty() ? element : element + " '" + name + "'";
}

double number(const tinygltf::ExtensionMap& extensions, const char* extension, const char* key,
              double fallback) {
    const auto it = extensions.find(extension);
    if (it == extensions.end() || !it->second.Has(key)) return fallback;
    const tinygltf::Value& v = it->second.Get(key);
    return v.IsNumber() ? v.GetNumberAsDouble() : fallback;
}

glm::vec3 rgb(const std::vector<double>& v, glm::vec3 fallback) {
    if (v.size() < 3) return fallback;
    return {float(v[0]), float(v[1]), float(v[2])};
}

// An extension's colour: three numbers, or a negative one where the value is not (so that
// finite_non_negative refuses it).
glm::vec3 value_rgb(const tinygltf::Value& c) {
    glm::vec3 color(-1.0f);
    if (!c.IsArray() || c.ArrayLen() != 3) return color;
    for (int k = 0; k < 3; ++k) {
        const tinygltf::Value& v = c.Get(k);
        color[k] = v.IsNumber() ? float(v.GetNumberAsDouble()) : -1.0f;
    }
    return color;
}

bool finite_non_negative(glm::vec3 c) {
    return std::isfinite(c.x) && std::isfinite(c.y) && std::isfinite(c.z) && c.x >= 0.0f &&
           c.y >= 0.0f && c.z >= 0.0f;
}

// The bytes of an image stored in a buffer view, checked to lie inside the buffer.
std::span<const std::uint8_t> buffer_view_bytes(const tinygltf::Model& model, int view_index,
                                                std::string& problem) {
    if (std::size_t(view_index) >= model.bufferViews.size()) {
        problem = "bufferView " + std::to_string(view_index) + " is out of range";
        return {};
    }
    const tinygltf::BufferView& view = model.bufferViews[std::size_t(view_index)];
    if (view.buffer < 0 || std::size_t(view.buffer) >= model.buffers.size()) {
        problem = "bufferViews[" + std::to_string(view_index) + "].buffer is out of range";
        return {};
    }
    const std::vector<unsigned char>& data = model.buffers[std::size_t(view.buffer)].data;
    if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset) {
        problem = "bufferViews[" + std::to_string(view_index) + "] (offset " +
                  std::to_string(view.byteOffset) + ", length " + std::to_string(view.byteLength) +
                  ") runs past the end of buffers[" + std::to_string(view.buffer) + "] (" +
                  std::to_string(data.size()) + " bytes)";
        return {};
    }
    return {data.data() + view.byteOffset, view.byteLength};
}

bool Converter::image_texture(int index, const std::string& element, Texture& out) {
    if (index < 0 || std::size_t(index) >= model.images.size())
        fail(element, "source " + std::to_string(index) + " is out of range (the file has " +
                          std::to_string(model.images.size()) + " images)");
    const tinygltf::Image& image = model.images[std::size_t(index)];
    const std::string what = "images[" + std::to_string(index) + "]";
    if (auto it = images.textures.find(index); it != images.textures.end()) {
        out = it->second;
        return true;
    }
    if (auto it = images.errors.find(index); it != images.errors.end()) {
        warn(element,
             what + " cannot be decoded (" + it->second + "): the base colour alone is used");
        return false;
    }
    if (image.bufferView >= 0) {
        std::string problem;
        const auto bytes = buffer_view_bytes(model, image.bufferView, problem);
        try {
            if (!problem.empty()) throw ImageFileError(problem);
            out = decode_texture(bytes, image_name(images.file, index, image), kMaxEmbeddedTexels);
            images.textures[index] = out;
            return true;
        } catch (const ImageFileError& e) {
            images.errors[index] = e.what();
            warn(element,
                 what + " cannot be decoded (" + e.what() + "): the base colour alone is used");
            return false;
        }
    }
    if (image.uri.empty()) {
        warn(element, what + " has no data: the base colour alone is used");
        return false;
    }
    if (base_dir.empty()) {
        warn(element, what + ": external image '" + image.uri +
                          "' is not read when loading from memory: the base colour alone is used");
        return false;
    }
    try {
        out = load_texture(base_dir + "/" + uri_decode(image.uri));
        return true;
    } catch (const ImageFileError& e) {
        warn(element, what + " '" + image.uri + "' cannot be loaded (" + e.what() +
                          "): the base colour alone is used");
        return false;
    }
}

// One wrap mode for both axes: CLAMP_TO_EDGE is Extend, MIRRORED_REPEAT Mirror.
TextureWrap Converter::wrap_of(int sampler, const std::string& element) {
    if (sampler < 0) return TextureWrap::Repeat;
    if (std::size_t(sampler) >= model.samplers.size())
        fail(element, "sampler " + std::to_string(sampler) + " is out of range (the file has " +
                          std::to_string(model.samplers.size()) + " samplers)");
    const tinygltf::Sampler& s = model.samplers[std::size_t(sampler)];
    if (s.wrapS != s.wrapT)
        warn(element,
             "samplers[" + std::to_string(sampler) + "] wraps s and t differently: both use wrapS");
    if (s.wrapS == kWrapClamp) return TextureWrap::Extend;
    if (s.wrapS == kWrapMirror) return TextureWrap::Mirror;
    return TextureWrap::Repeat;
}

int Converter::texture(const tinygltf::TextureInfo& info, const std::string& element) {
    if (info.index < 0) return -1;
    if (std::size_t(info.index) >= model.textures.size())
        fail(element, "index " + std::to_string(info.index) + " is out of range (the file has " +
                          std::to_string(model.textures.size()) + " textures)");
    if (info.texCoord != 0)
        warn(element, "uses TEXCOORD_" + std::to_string(info.texCoord) + ": TEXCOORD_0 is used");
    if (info.extensions.count("KHR_texture_transform"))
        warn(element, "KHR_texture_transform is not supported: ignored");
    if (auto it = scene_texture.find(info.index); it != scene_texture.end()) return it->second;
    const tinygltf::Texture& t = model.textures[std::size_t(info.index)];
    const std::string what = element + " (textures[" + std::to_string(info.index) + "])";
    if (t.source < 0) {
        warn(what, "has no image source: the base colour alone is used");
        return scene_texture[info.index] = -1;
    }
    Texture texture;
    if (!image_texture(t.source, what, texture)) return scene_texture[info.index] = -1;
    texture.wrap = wrap_of(t.sampler, what);
    // magFilter NEAREST is Closest, as Blender's glTF importer sets the Image Texture (the
    // renderer has no mip levels, so minFilter has nothing to choose).
    if (t.sampler >= 0 && model.samplers[std::size_t(t.sampler)].magFilter == kFilterNearest)
        texture.interpolation = TextureInterpolation::Closest;
    scene.textures.push_back(std::move(texture));
    return scene_texture[info.index] = int(scene.textures.size()) - 1;
}

// A part of a material tree (a Mix's child), appended after the roots; its index.
int Converter::part(const Material& m) {
    scene.materials.push_back(m);
    return int(scene.materials.size()) - 1;
}

// Mix of parts a and b, b picked with probability factor (times the texture's channel). Its
// emission is the expected one, for the photons and light samples it starts.
Material Converter::mix_of(int a, int b, float factor, int texture, TextureChannel channel) {
    Material m;
    m.kind = MaterialKind::Mix;
    m.mix_a = a;
    m.mix_b = b;
    m.mix_factor = std::clamp(factor, 0.0f, 1.0f);
    m.mix_texture = texture;
    m.mix_channel = channel;
    const float f = m.mix_factor * (texture >= 0 ? 0.5f : 1.0f);
    const Material& ma = scene.materials[std::size_t(a)];
    const Material& mb = scene.materials[std::size_t(b)];
    m.emission = (1.0f - f) * ma.emission + f * mb.emission;
    m.emission_two_sided = ma.emission_two_sided;
    m.color = glm::vec3(0.0f);
    return m;
}

// a and b mixed, or one of them alone where the factor is 0 or a constant 1.
Material Converter::mix(const Material& a, const Material& b, float factor, int texture,
                        TextureChannel channel) {
    if (!(factor > 0.0f)) return a;  // NaN too
    if (texture < 0 && factor >= 1.0f) return b;
    return mix_of(part(a), part(b), factor, texture, channel);
}

// A texture of numbers (metallicRoughness, transmission): its bytes are linear, not sRGB.
int Converter::data_texture(const tinygltf::TextureInfo& info, const std::string& element) {
    const int k = texture(info, element);
    if (k < 0) return -1;
    if (auto it = linear_copy.find(k); it != linear_copy.end()) return it->second;
    Texture t = scene.textures[std::size_t(k)];
    if (!t.srgb8.empty()) {
        t.linear.resize(t.srgb8.size());
        for (std::size_t i = 0; i < t.srgb8.size(); ++i) t.linear[i] = float(t.srgb8[i]) / 255.0f;
        t.srgb8.clear();
    }
    scene.textures.push_back(std::move(t));
    return linear_copy[k] = int(scene.textures.size()) - 1;
}

// alphaMode MASK with a texture: coverage (alpha factor times the texel's alpha) compared
// with the cutoff once, here, into a texture of 0s and 1s.
int Converter::mask_texture(int k, float alpha, float cutoff) {
    Texture t = scene.textures[std::size_t(k)];
    const std::size_t texels = std::size_t(t.width) * std::size_t(t.height);
    std::vector<float> covered(texels * 4);
    for (std::size_t i = 0; i < texels; ++i) {
        const float a = t.srgb8.empty() ? t.linear[4 * i + 3] : float(t.srgb8[4 * i + 3]) / 255.0f;
        const float c = alpha * a >= cutoff ? 1.0f : 0.0f;
        for (int j = 0; j < 4; ++j) covered[4 * i + std::size_t(j)] = c;
    }
    t.srgb8.clear();
    t.linear = std::move(covered);
    scene.textures.push_back(std::move(t));
    return int(scene.textures.size()) - 1;
}

// KHR_materials_volume as Beer-Lambert's sigma_a: white light that runs attenuationDistance
// (world units) inside keeps attenuationColor, so sigma_a = -ln(attenuationColor) /
// attenuationDistance; the default infinite distance absorbs nothing. thicknessFactor and
// thicknessTexture are a rasterizer's stand-in for the path length inside, which rays
// measure: they are not read.
glm::vec3 Converter::volume_absorption(const tinygltf::ExtensionMap& extensions,
                                       const std::string& element) {
    const auto it = extensions.find("KHR_materials_volume");
    if (it == extensions.end()) return glm::vec3(0.0f);
    const double distance = number(extensions, "KHR_materials_volume", "attenuationDistance",
                                   std::numeric_limits<double>::infinity());
    if (!(distance > 0.0))
        fail(element, "KHR_materials_volume.attenuationDistance " + number_text(distance) +
                          " must be > 0");
    glm::vec3 color(1.0f);
    if (it->second.Has("attenuationColor")) {
        const tinygltf::Value& c = it->second.Get("attenuationColor");
        if (!c.IsArray() || c.ArrayLen() != 3)
            fail(element, "KHR_materials_volume.attenuationColor must be 3 numbers");
        for (int k = 0; k < 3; ++k) {
            const tinygltf::Value& v = c.Get(k);
            color[k] = v.IsNumber() ? float(v.GetNumberAsDouble()) : -1.0f;
        }
    }
    if (!finite_non_negative(color) || color.x > 1.0f || color.y > 1.0f || color.z > 1.0f)
        fail(element, "KHR_materials_volume.attenuationColor must be 3 numbers in [0, 1]");
    if (std::isinf(distance)) return glm::vec3(0.0f);
    // A black channel would absorb everything at once (an infinite sigma_a): one part in a
    // million left at the attenuation distance stands for it.
    const glm::vec3 kept = glm::max(color, glm::vec3(1.0e-6f));
    return -glm::log(kept) / float(distance);
}

// glTF's metallic-roughness model (glTF 2.0 appendix B) as a tree of Mix materials:
//   alpha: Mix(transparent, coat(metallic mix)), coat: Mix(Fresnel(1.5), base,
//   Mix(clearcoat, base, white GGX)), metallic: Mix(metallic, Mix(transmission, plastic,
//   dielectric), conductor).
// The conductor has Schlick Fresnel from the base colour (as the specification's fresnel_mix
// of the base colour); the plastic is a white dielectric layer of the specification's F0
// (from KHR_materials_ior, scaled by KHR_materials_specular's factor) over a Lambert base;
// transmission is a rough dielectric tinted by the base colour. metallicRoughnessTexture's
// blue channel scales metallic and green roughness; transmissionTexture's red scales
// transmission. Roughness is glTF's perceptual roughness, Blender's (alpha = roughness^2).
Material Converter::material(const tinygltf::Material& m, const std::string& element) {
    const tinygltf::PbrMetallicRoughness& pbr = m.pbrMetallicRoughness;
    Material base;
    base.color = rgb(pbr.baseColorFactor, glm::vec3(1.0f));
    if (!finite_non_negative(base.color))
        fail(element, "pbrMetallicRoughness.baseColorFactor must be finite and >= 0");
    const float strength =
        float(number(m.extensions, "KHR_materials_emissive_strength", "emissiveStrength", 1.0));
    base.emission = rgb(m.emissiveFactor, glm::vec3(0.0f)) * strength;
    // glTF's single-sided materials are seen (and so emit) from the front only.
    base.emission_two_sided = m.doubleSided;
    if (!finite_non_negative(base.emission))
        fail(element, "emissiveFactor times emissiveStrength must be finite and >= 0");
    base.color_texture =
        texture(pbr.baseColorTexture, element + ".pbrMetallicRoughness.baseColorTexture");
    float roughness = float(pbr.roughnessFactor);
    if (!(roughness >= 0.0f && roughness <= 1.0f)) {
        warn(element, "pbrMetallicRoughness.roughnessFactor " + number_text(roughness) +
                          " is outside [0, 1]: clamped");
        roughness = std::isnan(roughness) ? 1.0f : std::clamp(roughness, 0.0f, 1.0f);
    }
    base.roughness = roughness;
    const int metal_roughness = data_texture(
        pbr.metallicRoughnessTexture, element + ".pbrMetallicRoughness.metallicRoughnessTexture");
    if (metal_roughness >= 0) {
        base.roughness_texture = metal_roughness;
        base.roughness_channel = TextureChannel::Green;
    }

    const float ior = float(number(m.extensions, "KHR_materials_ior", "ior", 1.5));
    if (!(ior >= 1.0f && std::isfinite(ior)))
        fail(element, "KHR_materials_ior.ior " + number_text(ior) + " must be >= 1");
    const float specular =
        float(number(m.extensions, "KHR_materials_specular", "specularFactor", 1.0));
    // specularColorFactor multiplies the index's F0 (min(F0 color, 1) in the specification):
    // a grey one exactly, a tinted one by its mean. Blender's exporter writes Specular 0 as a
    // black specularColorFactor; read as white it was a layer of F0 0.034 that made a Cornell
    // box of such walls 3.3% brighter than the add-on's render of the .blend (issue 30).
    float specular_color = 1.0f;
    if (auto it = m.extensions.find("KHR_materials_specular"); it != m.extensions.end()) {
        if (it->second.Has("specularColorFactor")) {
            const glm::vec3 tint = value_rgb(it->second.Get("specularColorFactor"));
            if (!finite_non_negative(tint))
                fail(element, "KHR_materials_specular.specularColorFactor must be 3 numbers >= 0");
            specular_color = (tint.x + tint.y + tint.z) / 3.0f;
            if (std::max({tint.x, tint.y, tint.z}) - std::min({tint.x, tint.y, tint.z}) > 1e-6f)
                warn(element, "KHR_materials_specular.specularColorFactor's tint is not "
                              "rendered (its mean is)");
        }
        if (it->second.Has("specularTexture") || it->second.Has("specularColorTexture"))
            warn(element, "KHR_materials_specular's textures are not supported: its factor "
                          "alone is used");
    }
    // The layer's index: the specification's F0 = min(((ior - 1) / (ior + 1))^2 times the
    // specular colour, 1) times the specular factor, as an index of that reflectance.
    const float f0_color =
        std::min(std::pow((ior - 1.0f) / (ior + 1.0f), 2.0f) * specular_color, 1.0f);
    const float f0 = std::clamp(f0_color * std::max(specular, 0.0f), 0.0f, 0.999f);

    Material conductor = base;
    conductor.kind = MaterialKind::Conductor;
    conductor.schlick = true;
    Material plastic = base;
    plastic.kind = MaterialKind::Plastic;
    plastic.ior = (1.0f + std::sqrt(f0)) / (1.0f - std::sqrt(f0));
    Material glass = base;
    glass.kind = MaterialKind::Dielectric;
    glass.ior = ior;

    const float transmission =
        float(number(m.extensions, "KHR_materials_transmission", "transmissionFactor", 0.0));
    int transmission_texture = -1;
    if (auto it = m.extensions.find("KHR_materials_transmission");
        it != m.extensions.end() && it->second.Has("transmissionTexture")) {
        tinygltf::TextureInfo info;
        const tinygltf::Value& t = it->second.Get("transmissionTexture");
        if (t.Has("index") && t.Get("index").IsInt()) info.index = t.Get("index").GetNumberAsInt();
        if (t.Has("texCoord") && t.Get("texCoord").IsInt())
            info.texCoord = t.Get("texCoord").GetNumberAsInt();
        transmission_texture =
            data_texture(info, element + ".KHR_materials_transmission.transmissionTexture");
    }
    const float metallic = float(pbr.metallicFactor);
    Material out = mix(mix(plastic, glass, transmission, transmission_texture, TextureChannel::Red),
                       conductor, metallic, metal_roughness, TextureChannel::Blue);

    const float clearcoat =
        float(number(m.extensions, "KHR_materials_clearcoat", "clearcoatFactor", 0.0));
    if (clearcoat > 0.0f) {
        warn(element, "KHR_materials_clearcoat is approximated by a Fresnel-weighted white "
                      "reflection (index 1.5); its darkening of the layer below is not "
                      "rendered and its textures are not read");
        Material coat;
        coat.kind = MaterialKind::Conductor;
        coat.color = glm::vec3(1.0f);
        coat.roughness = std::clamp(
            float(number(m.extensions, "KHR_materials_clearcoat", "clearcoatRoughnessFactor", 0.0)),
            0.0f, 1.0f);
        coat.emission = base.emission;
        coat.emission_two_sided = base.emission_two_sided;
        const int under = part(out);
        const Material coated = mix_of(under, part(coat), std::min(clearcoat, 1.0f), -1,
                                       TextureChannel::Luminance);
        out = mix_of(under, part(coated), 0.5f, -1, TextureChannel::Luminance);
        out.mix_mode = MixFactor::LayerFresnel;
        out.mix_ior = 1.5f;
    }

    const float alpha = pbr.baseColorFactor.size() >= 4 ? float(pbr.baseColorFactor[3]) : 1.0f;
    Material clear;
    clear.kind = MaterialKind::Transparent;
    clear.color = glm::vec3(1.0f);
    clear.emission_two_sided = base.emission_two_sided;
    if (m.alphaMode == "BLEND") {
        // Coverage as the probability of the surface, the rest passing straight through.
        out = mix(clear, out, alpha, base.color_texture, TextureChannel::Alpha);
    } else if (m.alphaMode == "MASK") {
        const float cutoff = float(m.alphaCutoff);
        if (base.color_texture >= 0)
            out = mix(clear, out, 1.0f, mask_texture(base.color_texture, alpha, cutoff),
                      TextureChannel::Alpha);
        else
            out = mix(clear, out, alpha >= cutoff ? 1.0f : 0.0f, -1, TextureChannel::Alpha);
    } else if (m.alphaMode != "OPAQUE") {
        warn(element, "alphaMode " + m.alphaMode + " is not one of OPAQUE, MASK, BLEND: "
                      "rendered opaque");
    }
    // emissiveTexture (sRGB, as the base colour's) multiplies emissiveFactor on the whole
    // material, the root of its Mix tree.
    if (m.emissiveTexture.index >= 0)
        out.emission_texture = texture(m.emissiveTexture, element + ".emissiveTexture");
    if (m.normalTexture.index >= 0) {
        // Tangent space, +Y up as Blender's; the texels are numbers (linear). glTF's scale
        // (x and y of the texel times it) becomes the Normal Map's Strength, as Blender's
        // importer maps it: equal at 1, close for tilts below 45 degrees.
        tinygltf::TextureInfo info;
        info.index = m.normalTexture.index;
        info.texCoord = m.normalTexture.texCoord;
        info.extensions = m.normalTexture.extensions;
        out.normal_texture = data_texture(info, element + ".normalTexture");
        const double scale = m.normalTexture.scale;
        if (!std::isfinite(scale) || scale < 0.0)
            fail(element, "normalTexture.scale must be finite and >= 0");
        out.normal_strength = float(scale);
    }
    // Read on the root, as the shaders read it: the glass leaf's inside is the object's.
    out.absorption = volume_absorption(m.extensions, element);
    return out;
}

}  // namespace

bool decode_image(tinygltf::Image* image, int image_index, std::string*, std::string*, int, int,
                  const unsigned char* bytes, int size, void* user_data) {
    auto& images = *static_cast<DecodedImages*>(user_data);
    // Images in buffer views are decoded later, by buffer_view_bytes: tinygltf 2.7.0 hands
    // over byteLength bytes without checking that the view lies inside its buffer (found by
    // fuzz/gltf_fuzz.cpp: a heap overflow).
    if (image->bufferView >= 0) return true;
    const std::string name = image_name(images.file, image_index, *image);
    try {
        Texture t =
            decode_texture({bytes, size > 0 ? std::size_t(size) : 0}, name, kMaxEmbeddedTexels);
        image->width = t.width;
        image->height = t.height;
        images.textures[image_index] = std::move(t);
    } catch (const ImageFileError& e) {
        images.errors[image_index] = e.what();
    }
    return true;
}

void convert_materials(const tinygltf::Model& model, DecodedImages& images,
                       const std::string& base_dir, Scene& scene,
                       std::vector<std::string>& warnings) {
    Converter c{model, images, base_dir, scene, warnings, {}, {}};
    // The roots keep the glTF indices; the parts of Mix materials follow them.
    const std::size_t first = scene.materials.size();
    scene.materials.resize(first + model.materials.size());
    for (std::size_t i = 0; i < model.materials.size(); ++i) {
        const std::string element =
            display_name("materials[" + std::to_string(i) + "]", model.materials[i].name);
        Material root = c.material(model.materials[i], element);
        scene.materials[first + i] = root;
    }
}

}  // namespace glslppm::gltf
