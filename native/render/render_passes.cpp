#include "render/render_passes.h"

#include "render/gpu_layout.h"

#include <algorithm>
#include <bit>
#include <stdexcept>

namespace glslppm {

const std::vector<RenderPassInfo>& render_pass_catalog() {
    static const std::vector<RenderPassInfo> catalog = {
        {RenderPass::Depth, "depth", "Depth", "PASS_DEPTH", 1, "Z", false},
        {RenderPass::Normal, "normal", "Normal", "PASS_NORMAL", 3, "XYZ", false},
        {RenderPass::DenoisingNormal, "denoising_normal", "Denoising Normal",
         "PASS_DENOISING_NORMAL", 3, "XYZ", false},
        {RenderPass::DenoisingAlbedo, "denoising_albedo", "Denoising Albedo",
         "PASS_DENOISING_ALBEDO", 3, "RGB", false},
        {RenderPass::Emission, "emission", "Emission", "PASS_EMISSION", 3, "RGB", true},
        {RenderPass::Environment, "environment", "Environment", "PASS_ENVIRONMENT", 3, "RGB", true},
        {RenderPass::Direct, "direct", "Direct", "PASS_DIRECT", 3, "RGB", true},
        {RenderPass::Indirect, "indirect", "Indirect", "PASS_INDIRECT", 3, "RGB", true},
        {RenderPass::Caustics, "caustics", "Caustics", "PASS_CAUSTICS", 3, "RGB", true},
    };
    return catalog;
}

const RenderPassInfo& render_pass_info(RenderPass pass) {
    return render_pass_catalog()[static_cast<std::size_t>(pass)];
}

namespace {
std::string known_names() {
    std::string names;
    for (const RenderPassInfo& p : render_pass_catalog()) names += std::string(", ") + p.name;
    return "combined, all" + names;
}
}  // namespace

RenderPass parse_render_pass(const std::string& name) {
    for (const RenderPassInfo& p : render_pass_catalog())
        if (name == p.name) return p.pass;
    throw std::invalid_argument("passes: '" + name + "' is not a render pass (" + known_names() +
                                ")");
}

std::vector<RenderPass> parse_render_pass_list(const std::string& list) {
    std::vector<RenderPass> passes;
    std::size_t start = 0;
    while (start <= list.size()) {
        const std::size_t end = std::min(list.find(',', start), list.size());
        const std::string name = list.substr(start, end - start);
        if (name == "all") {
            for (const RenderPassInfo& p : render_pass_catalog()) passes.push_back(p.pass);
        } else if (name != "combined") {
            passes.push_back(parse_render_pass(name));  // "" too: a clear error
        }
        start = end + 1;
    }
    return passes;
}

std::string render_pass_blender_3x(RenderPass pass) {
    // Blender 4.0 spelled the built-in passes out ("Emit" -> "Emission", "Env" ->
    // "Environment"); the others kept their names.
    if (pass == RenderPass::Emission) return "Emit";
    if (pass == RenderPass::Environment) return "Env";
    return render_pass_info(pass).blender;
}

int PassLayout::offset(RenderPass pass) const {
    int at = 0;
    for (RenderPass p : passes) {
        if (p == pass) return at;
        at += p == RenderPass::Direct && direct_photons ? 4 : 2;
    }
    return -1;
}

PassLayout pass_layout(const std::vector<RenderPass>& enabled, bool direct_photons,
                       int light_groups) {
    PassLayout layout;
    for (const RenderPassInfo& p : render_pass_catalog())
        if (std::find(enabled.begin(), enabled.end(), p.pass) != enabled.end())
            layout.passes.push_back(p.pass);
    auto has = [&](RenderPass p) {
        return std::find(layout.passes.begin(), layout.passes.end(), p) != layout.passes.end();
    };
    layout.direct_photons = direct_photons && has(RenderPass::Direct);
    layout.photon_split =
        layout.direct_photons || has(RenderPass::Indirect) || has(RenderPass::Caustics);
    for (RenderPass p : layout.passes)
        layout.stride += p == RenderPass::Direct && layout.direct_photons ? 4 : 2;
    layout.light_groups = light_groups;
    layout.light_group_first = layout.stride;
    layout.stride += 4 * light_groups;
    return layout;
}

std::vector<std::pair<std::string, std::string>> pass_defines(const PassLayout& layout) {
    std::vector<std::pair<std::string, std::string>> defines;
    if (layout.stride == 0) return defines;
    defines.push_back({"PASS_STRIDE", std::to_string(layout.stride) + "u"});
    if (layout.light_groups > 0) {
        defines.push_back({"LIGHT_GROUPS", std::to_string(layout.light_groups)});
        defines.push_back({"LIGHT_GROUP_FIRST", std::to_string(layout.light_group_first) + "u"});
    }
    for (RenderPass p : layout.passes)
        defines.push_back({render_pass_info(p).define, std::to_string(layout.offset(p)) + "u"});
    if (layout.photon_split) defines.push_back({"PASS_PHOTON_SPLIT", "1"});
    if (layout.direct_photons) defines.push_back({"PASS_DIRECT_PHOTONS", "1"});
    return defines;
}

namespace {

// One image from an eye pair at `eye_at` and a photon pair at `photon_at` (-1: none).
std::vector<float> resolve_pass_pairs(const PassLayout& layout, int eye_at, int photon_at,
                                      const std::vector<glm::vec4>& pass_films,
                                      const std::vector<glm::vec4>& pixel_stats,
                                      std::size_t pixels, const PassResolve& resolve) {
    const bool eye = eye_at >= 0, photon_pair = photon_at >= 0;
    const int at = eye_at;
    std::vector<float> out(pixels * 4, 0.0f);
    for (std::size_t i = 0; i < pixels; ++i) {
        const glm::vec4* record = &pass_films[i * static_cast<std::size_t>(layout.stride)];
        glm::vec3 value(0.0f);
        // As resolve_film.comp computes Combined's parts, in the same float operations.
        if (eye) value += glm::vec3(record[at]) * resolve.inv_passes;
        if (photon_pair) {
            const glm::vec3 tau(record[photon_at]);
            if (resolve.mean_of_passes) {
                value += tau * resolve.inv_passes;
            } else {
                const float r = pixel_stats[2 * i + 1].x;
                const float pi = 3.14159265358979f;
                value += tau * (resolve.inv_photons_emitted / (pi * r * r));
            }
        }
        out[4 * i + 0] = value.x;
        out[4 * i + 1] = value.y;
        out[4 * i + 2] = value.z;
        out[4 * i + 3] = 1.0f;
    }
    return out;
}

}  // namespace

std::vector<float> resolve_render_pass(const PassLayout& layout, RenderPass pass,
                                       const std::vector<glm::vec4>& pass_films,
                                       const std::vector<glm::vec4>& pixel_stats,
                                       std::size_t pixels, const PassResolve& resolve) {
    const int at = layout.offset(pass);
    if (at < 0)
        throw std::invalid_argument(std::string("render pass '") + render_pass_info(pass).name +
                                    "' was not enabled in the settings' passes");
    const bool photons = pass == RenderPass::Indirect || pass == RenderPass::Caustics;
    const bool eye = !photons;
    const bool photon_pair = photons || (pass == RenderPass::Direct && layout.direct_photons);
    const int photon_at = pass == RenderPass::Direct ? at + 2 : at;
    return resolve_pass_pairs(layout, eye ? at : -1, photon_pair ? photon_at : -1, pass_films,
                              pixel_stats, pixels, resolve);
}

std::vector<float> resolve_light_group(const PassLayout& layout, int group,
                                       const std::vector<glm::vec4>& pass_films,
                                       const std::vector<glm::vec4>& pixel_stats,
                                       std::size_t pixels, const PassResolve& resolve) {
    if (group < 0 || group >= layout.light_groups)
        throw std::invalid_argument("light group " + std::to_string(group) +
                                    " is not one of the scene's " +
                                    std::to_string(layout.light_groups));
    const int at = layout.light_group_offset(group);
    return resolve_pass_pairs(layout, at, at + 2, pass_films, pixel_stats, pixels, resolve);
}

void add_light_group_splats(std::vector<float>& image, const std::vector<std::uint32_t>& words,
                            float scale, float pixel_area) {
    const float factor = scale / pixel_area;
    const std::size_t pixels = image.size() / 4, stride = kLightSplatBytes / 4;
    for (std::size_t i = 0; i < pixels; ++i)
        for (std::size_t c = 0; c < 3; ++c)
            image[4 * i + c] +=
                std::bit_cast<float>(words[i * stride + kLightSplatSumWord + c]) * factor;
}

std::string light_group_pass_name(const std::string& group) { return "Combined_" + group; }

std::vector<ExrPass> render_pass_layers(const std::vector<float>& film,
                                        const std::vector<RenderPass>& passes,
                                        const std::vector<std::vector<float>>& images,
                                        const std::vector<std::string>& light_groups,
                                        const std::vector<std::vector<float>>& group_images) {
    std::vector<ExrPass> layers = {{"Combined", "RGBA", film}};
    for (std::size_t k = 0; k < passes.size(); ++k) {
        const RenderPassInfo& info = render_pass_info(passes[k]);
        layers.push_back({info.blender, info.channel_names, images[k]});
    }
    for (std::size_t g = 0; g < group_images.size(); ++g)
        layers.push_back({light_group_pass_name(light_groups[g]), "RGB", group_images[g]});
    return layers;
}

}  // namespace glslppm
