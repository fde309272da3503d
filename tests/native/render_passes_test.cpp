// The render passes' catalogue, records and resolve (render/render_passes.h), without a GPU.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "render/render_passes.h"

namespace glslppm {
namespace {

TEST(RenderPasses, ListsParseAndRejectUnknownNames) {
    EXPECT_TRUE(parse_render_pass_list("combined").empty());
    EXPECT_EQ(parse_render_pass_list("all").size(), render_pass_catalog().size());
    const auto two = parse_render_pass_list("caustics,depth");
    ASSERT_EQ(two.size(), 2u);
    EXPECT_EQ(two[0], RenderPass::Caustics);
    EXPECT_EQ(two[1], RenderPass::Depth);
    try {
        parse_render_pass_list("depth,,normal");
        FAIL() << "an empty name was accepted";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("'' is not a render pass"), std::string::npos);
    }
    EXPECT_THROW(parse_render_pass("Depth"), std::invalid_argument);
    EXPECT_EQ(render_pass_blender_3x(RenderPass::Emission), "Emit");
    EXPECT_EQ(render_pass_blender_3x(RenderPass::Environment), "Env");
    EXPECT_STREQ(render_pass_info(RenderPass::Environment).blender, "Environment");
}

TEST(RenderPasses, LayoutKeepsCatalogOrderAndGivesDirectPhotonsASecondPair) {
    const PassLayout sampled =
        pass_layout({RenderPass::Caustics, RenderPass::Direct, RenderPass::Depth}, false);
    EXPECT_EQ(sampled.offset(RenderPass::Depth), 0);
    EXPECT_EQ(sampled.offset(RenderPass::Direct), 2);
    EXPECT_EQ(sampled.offset(RenderPass::Caustics), 4);
    EXPECT_EQ(sampled.offset(RenderPass::Normal), -1);
    EXPECT_EQ(sampled.stride, 6);
    EXPECT_TRUE(sampled.photon_split);
    const PassLayout photons = pass_layout({RenderPass::Direct, RenderPass::Caustics}, true);
    EXPECT_EQ(photons.offset(RenderPass::Caustics), 4);
    EXPECT_EQ(photons.stride, 6);
    EXPECT_TRUE(photons.direct_photons);
    // Data passes alone: no photon classes, and no pass defines at all without passes.
    EXPECT_FALSE(pass_layout({RenderPass::Depth, RenderPass::Direct}, false).photon_split);
    EXPECT_TRUE(pass_defines(pass_layout({}, true)).empty());
}

TEST(RenderPasses, ResolveIsTheMeanAndSppmsDensityEstimate) {
    const PassLayout layout = pass_layout({RenderPass::Depth, RenderPass::Indirect}, false);
    // One pixel: depth summed over 4 passes, Indirect's tau, radius 0.5.
    std::vector<glm::vec4> films = {glm::vec4(12.0f, 0, 0, 0), glm::vec4(0.0f),
                                    glm::vec4(2.0f, 4.0f, 6.0f, 0.0f), glm::vec4(0.0f)};
    std::vector<glm::vec4> stats = {glm::vec4(0.0f), glm::vec4(0.5f, 0, 0, 0)};
    PassResolve r;
    r.inv_passes = 0.25f;
    r.inv_photons_emitted = 1.0f / 1000.0f;
    const auto depth = resolve_render_pass(layout, RenderPass::Depth, films, stats, 1, r);
    EXPECT_FLOAT_EQ(depth[0], 3.0f);
    const auto indirect = resolve_render_pass(layout, RenderPass::Indirect, films, stats, 1, r);
    const double pi = 3.14159265358979;
    EXPECT_NEAR(indirect[1], 4.0 / (pi * 0.25 * 1000.0), 1e-9);
    r.mean_of_passes = true;  // the mean of the passes' own estimates
    EXPECT_FLOAT_EQ(resolve_render_pass(layout, RenderPass::Indirect, films, stats, 1, r)[2],
                    1.5f);
    EXPECT_THROW(resolve_render_pass(layout, RenderPass::Normal, films, stats, 1, r),
                 std::invalid_argument);
}

}  // namespace
}  // namespace glslppm
