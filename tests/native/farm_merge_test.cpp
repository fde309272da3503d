// The farm merge of render passes (render/farm_merge.h), without a GPU: every layer of the
// files weighted by their pass counts, the same names written back, other passes refused.
#include "render/farm_merge.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "image/exr.h"

namespace glslppm {
namespace {

// A 2 x 1 multi-layer job file of `passes` passes starting at `first`, whose Combined.R and
// Depth.Z hold `value` and 10 * value in both pixels.
FarmInput job(const std::string& path, std::uint64_t first, std::uint64_t passes, float value) {
    FarmInput in{path, {}};
    in.exr.width = 2;
    in.exr.height = 1;
    in.exr.multilayer = true;
    in.exr.channels["ViewLayer.Combined.R"] = {value, value};
    in.exr.channels["ViewLayer.Depth.Z"] = {10.0f * value, 10.0f * value};
    in.exr.attributes = {{"glslppm.estimator", "pppm"},
                         {"glslppm.seed", "0"},
                         {"glslppm.settings", "width=2;height=1"},
                         {"glslppm.scene_hash", "abc"},
                         {"glslppm.pass_ranges", format_pass_ranges({{first, first + passes}})},
                         {"glslppm.passes", std::to_string(passes)}};
    return in;
}

TEST(FarmMerge, WeightsEveryLayerByItsPasses) {
    // One pass of 1 and three of 5: the mean over four passes is (1 + 15) / 4 = 4.
    const ExrChannels merged =
        merge_farm_renders({job("a.exr", 0, 1, 1.0f), job("b.exr", 1, 3, 5.0f)});
    EXPECT_TRUE(merged.multilayer);
    ASSERT_EQ(merged.channels.size(), 2u);
    EXPECT_EQ(merged.channels.at("ViewLayer.Combined.R"), (std::vector<float>{4.0f, 4.0f}));
    EXPECT_EQ(merged.channels.at("ViewLayer.Depth.Z"), (std::vector<float>{40.0f, 40.0f}));
    EXPECT_EQ(merged.attributes.at("glslppm.pass_ranges"), "0-4");
    EXPECT_EQ(merged.attributes.at("glslppm.passes"), "4");
}

// The message merge_farm_renders refuses `other` with after a one-pass job a.exr.
std::string refusal(const FarmInput& other) {
    try {
        merge_farm_renders({job("a.exr", 0, 1, 1.0f), other});
    } catch (const FarmMergeError& e) {
        return e.what();
    }
    return "(merged)";
}

TEST(FarmMerge, RefusesFilesWhosePassesDiffer) {
    FarmInput without_depth = job("b.exr", 1, 3, 5.0f);
    without_depth.exr.channels.erase("ViewLayer.Depth.Z");
    without_depth.exr.channels["ViewLayer.Emit.R"] = {0.0f, 0.0f};
    EXPECT_EQ(refusal(without_depth),
              "b.exr: render passes differ from a.exr's: ViewLayer.Depth only in a.exr; "
              "ViewLayer.Emit only in b.exr");
    // The same passes with other channels (a Depth written as RGB) are named by channel.
    FarmInput rgb_depth = job("c.exr", 1, 3, 5.0f);
    rgb_depth.exr.channels["ViewLayer.Depth.R"] = {0.0f, 0.0f};
    EXPECT_EQ(refusal(rgb_depth),
              "c.exr: render passes differ from a.exr's: ViewLayer.Depth.R only in c.exr");
}

// Only an estimator of independent passes (render/density_estimator.h) merges.
TEST(FarmMerge, RefusesEstimatorsWhosePassesDependOnEachOther) {
    FarmInput sppm = job("s.exr", 1, 3, 5.0f);
    sppm.exr.attributes["glslppm.estimator"] = "sppm";
    EXPECT_EQ(refusal(sppm), "s.exr: glslppm.estimator is sppm: only pppm or vcm renders merge "
                             "(SPPM's "
                             "passes depend on each other)");
    FarmInput unknown = job("u.exr", 1, 3, 5.0f);
    unknown.exr.attributes["glslppm.estimator"] = "bdpt";  // no such estimator
    EXPECT_EQ(refusal(unknown), "u.exr: glslppm.estimator is bdpt: only pppm or vcm renders "
                                "merge (not an estimator)");
}

TEST(FarmMerge, FilesKeepTheirLayerNamesThroughAWriteAndRead) {
    const std::string path = ::testing::TempDir() + "farm_merge_test.exr";
    const FarmInput in = job(path, 0, 2, 0.25f);
    write_exr_file(path, in.exr);
    const ExrChannels back = read_exr_file(path);
    std::remove(path.c_str());
    EXPECT_TRUE(back.multilayer);
    EXPECT_EQ(back.width, 2);
    EXPECT_EQ(back.channels, in.exr.channels);
    EXPECT_EQ(back.attributes, in.exr.attributes);
}

}  // namespace
}  // namespace glslppm
