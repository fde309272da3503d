#include "loaders/gltf_accessors.h"

#include <cmath>
#include <cstring>
#include <limits>

#include "loaders/scene_file.h"

namespace glslppm::gltf {
namespace {

[[noreturn]] void fail(const std::string& file, const std::string& what, int accessor,
                       const std::string& problem) {
    throw SceneFileError(file + ": " + what + " (accessors[" + std::to_string(accessor) +
                         "]): " + problem);
}

// The bytes of one accessor: where element 0 starts, the stride and the element size, all
// checked to lie inside the buffer view and the view inside its buffer.
struct Span {
    const std::uint8_t* first = nullptr;  // null only when count is 0
    std::size_t stride = 0;
    std::size_t count = 0;
};

Span locate(const tinygltf::Model& model, int index, const std::string& what,
            const std::string& file) {
    const tinygltf::Accessor& a = model.accessors[std::size_t(index)];
    if (a.sparse.isSparse) fail(file, what, index, "sparse accessors are not supported");
    const int component = tinygltf::GetComponentSizeInBytes(std::uint32_t(a.componentType));
    const int components = tinygltf::GetNumComponentsInType(std::uint32_t(a.type));
    if (component <= 0)
        fail(file, what, index, "unknown componentType " + std::to_string(a.componentType));
    if (components <= 0) fail(file, what, index, "unknown type " + std::to_string(a.type));
    Span s;
    s.count = a.count;
    // Without a buffer view an accessor is all zeros until sparse values fill it (glTF 2.0
    // section 3.6.2.3); sparse accessors are not supported, so such an accessor is useless.
    if (a.bufferView < 0)
        fail(file, what, index, "has no bufferView (sparse data is not supported)");
    if (std::size_t(a.bufferView) >= model.bufferViews.size())
        fail(file, what, index,
             "bufferView " + std::to_string(a.bufferView) + " is out of range (the file has " +
                 std::to_string(model.bufferViews.size()) + ")");
    const tinygltf::BufferView& view = model.bufferViews[std::size_t(a.bufferView)];
    if (view.buffer < 0 || std::size_t(view.buffer) >= model.buffers.size())
        fail(file, what, index,
             "bufferViews[" + std::to_string(a.bufferView) + "].buffer " +
                 std::to_string(view.buffer) + " is out of range");
    const std::vector<unsigned char>& data = model.buffers[std::size_t(view.buffer)].data;
    const std::size_t element = std::size_t(component) * std::size_t(components);
    s.stride = view.byteStride ? view.byteStride : element;
    if (view.byteStride && (view.byteStride < element || view.byteStride % std::size_t(component)))
        fail(file, what, index,
             "byteStride " + std::to_string(view.byteStride) + " does not fit elements of " +
                 std::to_string(element) + " bytes");
    // Every element must lie in the view, and the view in the buffer. Counts are bounded by
    // the buffer size first, so that the products below cannot overflow.
    const std::size_t size = data.size();
    const bool view_fits = view.byteOffset <= size && view.byteLength <= size - view.byteOffset;
    if (!view_fits)
        fail(file, what, index,
             "bufferViews[" + std::to_string(a.bufferView) + "] (offset " +
                 std::to_string(view.byteOffset) + ", length " + std::to_string(view.byteLength) +
                 ") runs past the end of buffers[" + std::to_string(view.buffer) + "] (" +
                 std::to_string(size) + " bytes)");
    // (count - 1) * stride + element <= byteLength - byteOffset, without overflow.
    const std::size_t avail = a.byteOffset <= view.byteLength ? view.byteLength - a.byteOffset : 0;
    const bool fits = s.count == 0 || (a.byteOffset <= view.byteLength && element <= avail &&
                                       (s.count - 1) <= (avail - element) / s.stride);
    if (!fits)
        fail(file, what, index,
             std::to_string(s.count) + " elements from byteOffset " + std::to_string(a.byteOffset) +
                 " run past the end of bufferViews[" + std::to_string(a.bufferView) + "] (" +
                 std::to_string(view.byteLength) + " bytes)");
    if (s.count > 0) s.first = data.data() + view.byteOffset + a.byteOffset;
    return s;
}

template <typename T>
T load(const std::uint8_t* p) {
    T v;
    std::memcpy(&v, p, sizeof v);  // glTF data need not be aligned for T
    return v;
}

// glTF 2.0 section 3.11 (animation normalization), the same for attributes.
float component_value(const std::uint8_t* p, int type, bool normalized) {
    switch (type) {
        case TINYGLTF_COMPONENT_TYPE_FLOAT:
            return load<float>(p);
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
            return normalized ? load<std::uint8_t>(p) / 255.0f : load<std::uint8_t>(p);
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
            return normalized ? load<std::uint16_t>(p) / 65535.0f : load<std::uint16_t>(p);
        case TINYGLTF_COMPONENT_TYPE_BYTE:
            return normalized ? std::max(load<std::int8_t>(p) / 127.0f, -1.0f)
                              : load<std::int8_t>(p);
        case TINYGLTF_COMPONENT_TYPE_SHORT:
            return normalized ? std::max(load<std::int16_t>(p) / 32767.0f, -1.0f)
                              : load<std::int16_t>(p);
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
            return normalized ? float(load<std::uint32_t>(p) / 4294967295.0)
                              : float(load<std::uint32_t>(p));
        case TINYGLTF_COMPONENT_TYPE_INT:
            return float(load<std::int32_t>(p));
        default:
            return std::numeric_limits<float>::quiet_NaN();
    }
}

void check_index(const tinygltf::Model& model, int accessor, const std::string& what,
                 const std::string& file) {
    if (accessor < 0 || std::size_t(accessor) >= model.accessors.size())
        throw SceneFileError(file + ": " + what + ": accessor " + std::to_string(accessor) +
                             " is out of range (the file has " +
                             std::to_string(model.accessors.size()) + " accessors)");
}

}  // namespace

std::size_t accessor_count(const tinygltf::Model& model, int accessor, const std::string& what,
                           const std::string& file) {
    check_index(model, accessor, what, file);
    return model.accessors[std::size_t(accessor)].count;
}

std::vector<float> read_floats(const tinygltf::Model& model, int accessor, int components,
                               const std::string& what, const std::string& file) {
    check_index(model, accessor, what, file);
    const tinygltf::Accessor& a = model.accessors[std::size_t(accessor)];
    if (tinygltf::GetNumComponentsInType(std::uint32_t(a.type)) != components)
        fail(file, what, accessor,
             "expected " + std::to_string(components) +
                 " components per element, the accessor has type " + std::to_string(a.type));
    const Span s = locate(model, accessor, what, file);
    const int size = tinygltf::GetComponentSizeInBytes(std::uint32_t(a.componentType));
    std::vector<float> out(s.count * std::size_t(components), 0.0f);
    for (std::size_t i = 0; i < s.count; ++i) {
        const std::uint8_t* e = s.first + i * s.stride;
        for (int c = 0; c < components; ++c) {
            const float v = component_value(e + c * size, a.componentType, a.normalized);
            if (!std::isfinite(v))
                fail(file, what, accessor,
                     "element " + std::to_string(i) + " component " + std::to_string(c) + " is " +
                         (std::isnan(v) ? "NaN" : "infinite"));
            out[i * std::size_t(components) + std::size_t(c)] = v;
        }
    }
    return out;
}

std::vector<std::uint32_t> read_indices(const tinygltf::Model& model, int accessor,
                                        const std::string& what, const std::string& file) {
    check_index(model, accessor, what, file);
    const tinygltf::Accessor& a = model.accessors[std::size_t(accessor)];
    if (a.type != TINYGLTF_TYPE_SCALAR) fail(file, what, accessor, "indices must be scalars");
    const Span s = locate(model, accessor, what, file);
    std::vector<std::uint32_t> out(s.count, 0u);
    for (std::size_t i = 0; i < s.count; ++i) {
        const std::uint8_t* e = s.first + i * s.stride;
        switch (a.componentType) {
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
                out[i] = load<std::uint8_t>(e);
                break;
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
                out[i] = load<std::uint16_t>(e);
                break;
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
                out[i] = load<std::uint32_t>(e);
                break;
            default:
                fail(file, what, accessor,
                     "indices must be unsigned byte, short or int (componentType " +
                         std::to_string(a.componentType) + ")");
        }
    }
    return out;
}

}  // namespace glslppm::gltf
