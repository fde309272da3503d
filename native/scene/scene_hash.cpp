#include "scene/scene_hash.h"

#include <cstdio>
#include <cstring>
#include <span>

namespace glslppm {
namespace {

// FNV-1a over 8-byte words with a final avalanche (splitmix64's): not cryptographic, only
// sure to differ when any value differs.
class Hasher {
public:
    explicit Hasher(const CancelFlag* cancel) : cancel_(cancel) {}

    void bytes(const void* data, std::size_t size) {
        const auto* p = static_cast<const unsigned char*>(data);
        std::size_t k = 0;
        for (; k + 8 <= size; k += 8) {
            if ((k & ((std::size_t(1) << 20) - 1)) == 0) throw_if_cancelled(cancel_);  // per MiB
            std::uint64_t w;
            std::memcpy(&w, p + k, 8);
            word(w);
        }
        std::uint64_t tail = 0;
        if (size > k) std::memcpy(&tail, p + k, size - k);
        word(tail ^ (static_cast<std::uint64_t>(size - k) << 56));
    }
    template <class T>
    void value(const T& v) { bytes(&v, sizeof v); }
    template <class T>
    void array(std::span<const T> a) {
        value(static_cast<std::uint64_t>(a.size()));
        bytes(a.data(), a.size_bytes());
    }
    std::uint64_t result() const {
        std::uint64_t z = h_;
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }

private:
    void word(std::uint64_t w) { h_ = (h_ ^ w) * 0x100000001B3ull; }
    std::uint64_t h_ = 0xCBF29CE484222325ull;
    const CancelFlag* cancel_;
};

// Vertex colours after a tag word, so that they never hash like tangents of another mesh;
// meshes without keep their old hash.
void colors(Hasher& h, std::span<const glm::vec3> c) {
    if (c.empty()) return;
    h.value(std::uint64_t{0x636F6C6F7273ull});  // "colors"
    h.array(c);
}

}  // namespace

std::uint64_t scene_hash_without_camera(const Scene& s, const CancelFlag* cancel) {
    Hasher h(cancel);
    h.array(s.mesh.positions);
    h.array(s.mesh.triangles);
    h.array(s.mesh.normals);
    h.array(s.mesh.uvs);
    h.array(s.mesh.material_ids);
    if (!s.mesh.tangents.empty()) h.array(s.mesh.tangents);  // scenes without keep their old hash
    colors(h, s.mesh.colors);
    // Instanced meshes in their own space and the instances placing them (scene.h).
    h.value(static_cast<std::uint64_t>(s.instance_meshes.size()));
    for (const MeshView& m : s.instance_meshes) {
        h.array(m.positions);
        h.array(m.triangles);
        h.array(m.normals);
        h.array(m.uvs);
        h.array(m.material_ids);
        if (!m.tangents.empty()) h.array(m.tangents);  // scenes without keep their old hash
        colors(h, m.colors);
    }
    h.value(static_cast<std::uint64_t>(s.instances.size()));
    for (const Instance& i : s.instances) {
        h.value(i.to_world);
        h.value(i.mesh);
        h.value(i.material_offset);
    }
    if (!s.motion.empty()) {  // scenes without motion keep their old hash
        const auto steps = [&](const TransformSteps& t) {
            h.value(static_cast<std::uint64_t>(t.times.size()));
            for (std::size_t k = 0; k < t.times.size(); ++k) {
                h.value(t.times[k]);
                h.value(t.to_world[k]);
            }
        };
        h.value(s.motion.shutter_open);
        h.value(s.motion.shutter_length);
        for (const InstanceMotion& m : s.motion.instances) {
            h.value(m.instance);
            steps(m.steps);
        }
        steps(s.motion.camera);
        for (float fov : s.motion.camera_fov_x) h.value(fov);
        for (const MeshDeformation& d : s.motion.meshes) {
            h.value(d.mesh);
            h.array(std::span<const float>(d.times));
            for (const auto& p : d.positions) h.array(std::span<const glm::vec3>(p));
            for (const auto& n : d.normals) h.array(std::span<const glm::vec3>(n));
        }
        for (const LightMotion& l : s.motion.lights) {
            h.value(l.light);
            steps(l.steps);
        }
    }
    h.value(static_cast<std::uint64_t>(s.materials.size()));
    for (const Material& m : s.materials) {
        h.value(m.kind);
        h.value(m.color);
        h.value(m.ior);
        h.value(m.emission);
        h.value(m.color_texture);
        h.value(static_cast<std::uint32_t>(m.emission_two_sided | m.visible_to_camera << 1 |
                                           m.casts_shadow << 2 |
                                           m.visible_in_reflections << 3));
        // The microfacet model's (scene.h).
        h.value(m.roughness);
        h.value(m.roughness_texture);
        h.value(m.roughness_channel);
        h.value(static_cast<std::uint32_t>(m.multiscatter | m.schlick << 1 | m.tint_reflection << 2));
        h.value(m.mix_a);
        h.value(m.mix_b);
        h.value(m.mix_factor);
        h.value(m.mix_texture);
        h.value(m.mix_channel);
        h.value(m.mix_mode);
        h.value(m.mix_ior);
        if (m.normal_texture >= 0) {  // materials without keep their old hash
            h.value(m.normal_texture);
            h.value(m.normal_strength);
        }
        if (m.emission_texture >= 0) h.value(m.emission_texture);
        if (m.vertex_color) h.value(std::uint64_t{0x766572746578ull});  // "vertex"
        if (m.f82_tint != glm::vec3(1.0f)) h.value(m.f82_tint);
        if (m.absorption != glm::vec3(0.0f)) h.value(m.absorption);
        if (m.bump_texture >= 0) {
            h.value(m.bump_texture);
            h.value(m.bump_strength);
            h.value(m.bump_distance);
        }
    }
    h.value(static_cast<std::uint64_t>(s.lights.size()));
    for (const Light& l : s.lights) {
        h.value(l.kind);
        h.value(l.color);
        h.value(l.power);
        h.value(l.position);
        h.value(l.direction);
        h.value(l.spot_size);
        h.value(l.spot_blend);
        h.value(l.radius);
        h.value(l.angle);
        h.value(l.to_world);
        h.value(l.shape);
        h.value(l.size_x);
        h.value(l.size_y);
        h.value(static_cast<std::uint32_t>(l.spot_cosine | l.visible_to_camera << 1 |
                                           l.facing_disc << 2));
    }
    h.value(static_cast<std::uint64_t>(s.textures.size()));
    for (const Texture& t : s.textures) {
        h.value(t.width);
        h.value(t.height);
        h.value(t.wrap);
        h.value(t.interpolation);
        h.value(t.uv_map_u);
        h.value(t.uv_map_v);
        h.value(static_cast<std::uint32_t>(t.from_position));
        h.value(t.position_map_u);
        h.value(t.position_map_v);
        h.array(std::span<const std::uint8_t>(t.srgb8));
        h.array(std::span<const float>(t.linear));
    }
    h.value(s.environment);
    h.value(s.environment_texture);
    h.value(s.environment_to_world);
    if (!s.light_groups.empty()) {  // scenes without groups keep their old hash
        h.value(static_cast<std::uint64_t>(s.light_groups.size()));
        for (const std::string& name : s.light_groups) {
            h.value(static_cast<std::uint64_t>(name.size()));
            for (const char c : name) h.value(static_cast<std::uint32_t>(c));
        }
        for (const Material& m : s.materials) h.value(m.light_group);
        for (const Light& l : s.lights) h.value(l.light_group);
        h.value(s.world_light_group);
    }
    if (!s.light_link_receives.empty()) {  // scenes without links keep their old hash
        h.array(std::span<const std::uint32_t>(s.light_link_receives));
        h.array(std::span<const std::uint32_t>(s.shadow_link_blocks));
        for (const Material& m : s.materials) h.value(m.light_link_set), h.value(m.light_link_row);
        for (const Light& l : s.lights) h.value(l.light_link_set);
    }
    return h.result();
}

std::uint64_t scene_hash_with_camera(std::uint64_t without_camera, const Camera& c) {
    Hasher h(nullptr);
    h.value(without_camera);
    h.value(c.to_world);
    for (float v : {c.fov_x, c.shift_x, c.shift_y, c.ortho_scale, c.aperture_radius,
                    c.focus_distance, c.pixel_aspect})
        h.value(v);
    h.value(c.projection);
    for (int v : {c.full_width, c.full_height, c.region_x, c.region_y}) h.value(v);
    return h.result();
}

std::uint64_t scene_hash(const Scene& scene, const CancelFlag* cancel) {
    return scene_hash_with_camera(scene_hash_without_camera(scene, cancel), scene.camera);
}

std::string scene_hash_hex(std::uint64_t hash) {
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
    return text;
}

std::string scene_hash_hex(const Scene& scene, const CancelFlag* cancel) {
    return scene_hash_hex(scene_hash(scene, cancel));
}

}  // namespace glslppm
