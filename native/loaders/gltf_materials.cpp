#include "loaders/gltf_materials.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
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

struct Converter {
    const tinygltf::Model& model;
    DecodedImages& images;
    const std::string& base_dir;
    Scene& scene;
    std::vector<std::string>& warnings;
    std::map<int, int> scene_texture;  // glTF textures[] index -> Scene::textures index

    void warn(const std::string& element, const std::string& what) {
        warnings.push_back(images.file + ": " + element + ": " + what);
    }
    [[noreturn]] void fail(const std::string& element, const std::string& what) const {
        throw SceneFileError(images.file + ": " + element + ": " + what);
    }

    bool image_texture(int index, const std::string& element, Texture& out);
    TextureWrap wrap_of(int sampler, const std::string& element);
    int texture(const tinygltf::TextureInfo& info, const std::string& element);
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

// One wrap mode for both axes: CLAMP_TO_EDGE becomes Clip, MIRRORED_REPEAT Repeat.
TextureWrap Converter::wrap_of(int sampler, const std::string& element) {
    if (sampler < 0) return TextureWrap::Repeat;
    if (std::size_t(sampler) >= model.samplers.size())
        fail(element, "sampler " + std::to_string(sampler) + " is out of range (the file has " +
                          std::to_string(model.samplers.size()) + " samplers)");
    const tinygltf::Sampler& s = model.samplers[std::size_t(sampler)];
    if (s.wrapS != s.wrapT)
        warn(element,
             "samplers[" + std::to_string(sampler) + "] wraps s and t differently: both use wrapS");
    if (s.wrapS == kWrapClamp) return TextureWrap::Clip;
    if (s.wrapS != kWrapRepeat)
        warn(element, "samplers[" + std::to_string(sampler) +
                          "]: mirrored repeat is not supported: repeated instead");
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
    scene.textures.push_back(std::move(texture));
    return scene_texture[info.index] = int(scene.textures.size()) - 1;
}

Material Converter::material(const tinygltf::Material& m, const std::string& element) {
    const tinygltf::PbrMetallicRoughness& pbr = m.pbrMetallicRoughness;
    Material out;
    out.color = rgb(pbr.baseColorFactor, glm::vec3(1.0f));
    if (!finite_non_negative(out.color))
        fail(element, "pbrMetallicRoughness.baseColorFactor must be finite and >= 0");
    const double metallic = pbr.metallicFactor;
    const double transmission =
        number(m.extensions, "KHR_materials_transmission", "transmissionFactor", 0.0);
    if (transmission >= 0.5) {
        out.kind = MaterialKind::Dielectric;
        out.ior = float(number(m.extensions, "KHR_materials_ior", "ior", 1.5));
        if (!(out.ior >= 1.0f && std::isfinite(out.ior)))
            fail(element, "KHR_materials_ior.ior " + number_text(out.ior) + " must be >= 1");
        if (transmission < 1.0)
            warn(element, "transmission " + number_text(transmission) +
                              " is rendered as fully transmissive glass");
    } else {
        out.kind = metallic >= 0.5 ? MaterialKind::Conductor : MaterialKind::Diffuse;
        if (transmission > 0.0)
            warn(element, "transmission " + number_text(transmission) + " below 0.5 is ignored");
        if (metallic > 0.0 && metallic < 1.0)
            warn(element, "metallicFactor " + number_text(metallic) + " is rendered as " +
                              (metallic >= 0.5 ? "a pure conductor" : "pure diffuse"));
    }
    if (out.kind != MaterialKind::Diffuse && pbr.roughnessFactor > 0.2)
        warn(element, "roughnessFactor " + number_text(pbr.roughnessFactor) +
                          " is rendered as a perfectly smooth surface");
    const float strength =
        float(number(m.extensions, "KHR_materials_emissive_strength", "emissiveStrength", 1.0));
    out.emission = rgb(m.emissiveFactor, glm::vec3(0.0f)) * strength;
    // glTF's single-sided materials are seen (and so emit) from the front only.
    out.emission_two_sided = m.doubleSided;
    if (!finite_non_negative(out.emission))
        fail(element, "emissiveFactor times emissiveStrength must be finite and >= 0");
    out.color_texture =
        texture(pbr.baseColorTexture, element + ".pbrMetallicRoughness.baseColorTexture");
    if (pbr.metallicRoughnessTexture.index >= 0)
        warn(element, "metallicRoughnessTexture is not supported: the factors decide");
    if (m.emissiveTexture.index >= 0)
        warn(element, "emissiveTexture is not supported: emissiveFactor alone is used");
    if (m.normalTexture.index >= 0) warn(element, "normalTexture is not supported: ignored");
    if (m.alphaMode != "OPAQUE")
        warn(element, "alphaMode " + m.alphaMode + " is not supported: rendered opaque");
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
    Converter c{model, images, base_dir, scene, warnings, {}};
    for (std::size_t i = 0; i < model.materials.size(); ++i) {
        const std::string element =
            display_name("materials[" + std::to_string(i) + "]", model.materials[i].name);
        scene.materials.push_back(c.material(model.materials[i], element));
    }
}

}  // namespace glslppm::gltf
