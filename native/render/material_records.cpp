// The material table as the shaders read it (GpuMaterial records, then the microfacet albedo
// tables); declared in scene_preparation.h.
#include "render/scene_preparation.h"

#include <algorithm>
#include <cstdint>
#include <string>

#include <glm/gtc/packing.hpp>

#include "render/microfacet_tables.h"
#include "scene/scene_validation.h"

namespace glslppm {

std::uint32_t normal_map_word(const Material& m) {
    const bool bump = m.bump_texture >= 0;
    const std::int32_t texture = bump ? m.bump_texture : m.normal_texture;
    if (texture < 0) return 0u;
    if (texture >= static_cast<std::int32_t>(kMaxNormalMapTextures))
        throw SceneError("a normal or bump map's texture index " + std::to_string(texture) +
                         " is past the " + std::to_string(kMaxNormalMapTextures - 1) +
                         " a material record holds");
    return static_cast<std::uint32_t>(texture + 1) | (bump ? kNormalMapBump : 0u) |
           glm::packHalf1x16(bump ? m.bump_strength : m.normal_strength) << 16;
}

// Whether a material has a lobe beyond Lambert, the mirror (a conductor of roughness 0 and
// Fresnel its colour) and smooth glass (untinted reflection): shaders/common/lobes.glsl
// compiles those lobes' code only then (HAS_ROUGH_LOBES).
bool needs_rough_lobes(const Material& m) {
    // The lobes bend a normal-mapped shading normal towards the surface (shading_at).
    if (m.normal_texture >= 0 || m.bump_texture >= 0) return true;
    switch (m.kind) {
        case MaterialKind::Diffuse: return false;
        case MaterialKind::Conductor:
            return m.roughness > 0.0f || m.roughness_texture >= 0 || m.schlick;
        case MaterialKind::Dielectric:
            return m.roughness > 0.0f || m.roughness_texture >= 0 || m.tint_reflection;
        default: return true;
    }
}

std::vector<glm::vec4> material_records(const std::vector<Material>& materials,
                                        const std::vector<std::uint32_t>& flags, bool textures,
                                        bool vertex_colors) {
    std::vector<GpuMaterial> records;
    std::vector<glm::vec4> tables;
    const std::int32_t tables_base = static_cast<std::int32_t>(materials.size() * kGpuMaterialVec4);
    auto add_table = [&](AlbedoLobe lobe, float ior) {
        const std::int32_t at = tables_base + static_cast<std::int32_t>(tables.size());
        const std::vector<float> t = albedo_table(lobe, ior);
        static_assert(kAlbedoTableFloats % 4 == 0);
        for (std::size_t i = 0; i < t.size(); i += 4) tables.push_back({t[i], t[i + 1], t[i + 2], t[i + 3]});
        return at;
    };
    std::int32_t conductor_table = -1;
    std::vector<std::pair<float, std::int32_t>> dielectric_tables, layer_tables;
    auto table_for = [&](std::vector<std::pair<float, std::int32_t>>& known, AlbedoLobe lobe,
                         float ior) {
        for (auto [i, at] : known)
            if (i == ior) return at;
        const std::int32_t at = add_table(lobe, ior);
        if (lobe == AlbedoLobe::DielectricOutside) add_table(AlbedoLobe::DielectricInside, ior);
        known.push_back({ior, at});
        return at;
    };
    for (std::size_t k = 0; k < materials.size(); ++k) {
        const Material& m = materials[k];
        GpuMaterial g{};
        g.flags = flags[k] | (vertex_colors && m.vertex_color ? kMaterialVertexColor : 0u);
        g.color = m.color;
        g.kind = static_cast<float>(m.kind);
        g.emission = m.emission;
        g.ior = m.ior;
        g.color_texture = textures ? m.color_texture : -1;
        g.roughness = m.roughness;
        g.roughness_texture = textures ? m.roughness_texture : -1;
        g.mix_a = m.mix_a;
        g.mix_b = m.mix_b;
        g.mix_factor = m.mix_factor;
        g.mix_texture = textures ? m.mix_texture : -1;
        g.mix_ior = m.mix_ior;
        g.options = static_cast<std::uint32_t>(m.roughness_channel) |
                    static_cast<std::uint32_t>(m.mix_channel) << kOptionMixChannelShift |
                    static_cast<std::uint32_t>(m.mix_mode) << kOptionMixModeShift |
                    (m.multiscatter ? kOptionMultiscatter : 0u) | (m.schlick ? kOptionSchlick : 0u) |
                    (m.tint_reflection ? kOptionTintReflection : 0u);
        g.table = -1;
        g.normal_map = textures ? normal_map_word(m) : 0u;
        g.emission_texture = textures ? m.emission_texture : -1;
        g.f82_tint = m.f82_tint;
        g.absorption = m.absorption;
        static_assert(MATERIAL_LINK_SET_SCALE == MATERIAL_LINK_ROW_SCALE * MAX_LIGHT_LINK_ROWS &&
                      MATERIAL_LINK_SET_SCALE * MAX_LIGHT_LINK_SETS <= (1 << 24));
        g.light_group_code = static_cast<float>(m.light_group + 1 +
                                                MATERIAL_LINK_ROW_SCALE * m.light_link_row +
                                                MATERIAL_LINK_SET_SCALE * m.light_link_set);
        if (textures && m.bump_texture >= 0)
            g.options |= glm::packHalf1x16(m.bump_distance) << kOptionBumpDistanceShift;
        const bool rough = m.roughness > 0.0f || m.roughness_texture >= 0;
        if (m.kind == MaterialKind::Conductor && rough && m.multiscatter) {
            if (conductor_table < 0) conductor_table = add_table(AlbedoLobe::WhiteConductor, 1.0f);
            g.table = conductor_table;
        } else if (m.kind == MaterialKind::Dielectric && rough && m.multiscatter) {
            g.table = table_for(dielectric_tables, AlbedoLobe::DielectricOutside, m.ior);
        } else if (m.kind == MaterialKind::Plastic) {
            g.table = table_for(layer_tables, AlbedoLobe::DielectricLayer, m.ior);
        }
        records.push_back(g);
    }
    std::vector<glm::vec4> out(records.size() * kGpuMaterialVec4);
    static_assert(sizeof(GpuMaterial) == kGpuMaterialVec4 * sizeof(glm::vec4));
    if (!records.empty()) std::memcpy(out.data(), records.data(), records.size() * sizeof(GpuMaterial));
    out.insert(out.end(), tables.begin(), tables.end());
    return out;
}

}  // namespace glslppm
