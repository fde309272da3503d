// Multi-part OpenEXR files (image/exr.h): Blender 5.x writes a multi-layer EXR as one part
// per pass. Every part is read back exactly, under its full channel names, and a farm merge
// of such files keeps every pass (render/farm_merge.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <ImfStringAttribute.h>

#include "image/exr.h"
#include "render/farm_merge.h"

namespace glslppm {
namespace {

constexpr int kWidth = 3, kHeight = 2;

// One part of a test file: its name and its channels by the name written in the part.
struct Part {
    std::string name;
    std::map<std::string, std::vector<float>> channels;
};

// Writes `parts` as a multi-part scanline file, the way Blender 5.x writes a multi-layer EXR
// (BlenderMultiChannel and `attributes` in the first part's header).
void write_multipart(const std::string& path, const std::vector<Part>& parts,
                     const std::map<std::string, std::string>& attributes = {}) {
    std::vector<Imf::Header> headers;
    for (std::size_t p = 0; p < parts.size(); ++p) {
        Imf::Header header(kWidth, kHeight);
        header.setName(parts[p].name);
        header.setType(Imf::SCANLINEIMAGE);
        if (p == 0) {
            header.insert("BlenderMultiChannel", Imf::StringAttribute("Blender V2.55.1 and newer"));
            for (const auto& [key, value] : attributes)
                header.insert(key, Imf::StringAttribute(value));
        }
        for (const auto& [channel, plane] : parts[p].channels)
            header.channels().insert(channel, Imf::Channel(Imf::FLOAT));
        headers.push_back(header);
    }
    Imf::MultiPartOutputFile out(path.c_str(), headers.data(), static_cast<int>(headers.size()));
    for (std::size_t p = 0; p < parts.size(); ++p) {
        Imf::OutputPart part(out, static_cast<int>(p));
        Imf::FrameBuffer frame;
        for (const auto& [channel, plane] : parts[p].channels)
            frame.insert(channel, Imf::Slice(Imf::FLOAT,
                                             const_cast<char*>(reinterpret_cast<const char*>(
                                                 plane.data())),
                                             sizeof(float), sizeof(float) * kWidth));
        part.setFrameBuffer(frame);
        part.writePixels(kHeight);
    }
}

// Six distinct values per channel, none of them exact in half precision.
std::vector<float> plane(float base) {
    std::vector<float> values;
    for (int i = 0; i < kWidth * kHeight; ++i) values.push_back(base + 0.1234567f * i);
    return values;
}

std::vector<Part> blender5_parts(float scale) {
    return {{"ViewLayer.Combined",
             {{"ViewLayer.Combined.R", plane(1.0f * scale)},
              {"ViewLayer.Combined.G", plane(2.0f * scale)},
              {"ViewLayer.Combined.B", plane(3.0f * scale)},
              {"ViewLayer.Combined.A", plane(4.0f * scale)}}},
            {"ViewLayer.Depth", {{"ViewLayer.Depth.Z", plane(5.0f * scale)}}},
            {"ViewLayer.Caustics",
             {{"ViewLayer.Caustics.R", plane(6.0f * scale)},
              {"ViewLayer.Caustics.G", plane(7.0f * scale)},
              {"ViewLayer.Caustics.B", plane(8.0f * scale)}}}};
}

TEST(ExrMultiPart, EveryPartIsReadBackExactly) {
    const std::string path = ::testing::TempDir() + "exr_multipart_test.exr";
    std::vector<Part> parts = blender5_parts(1.0f);
    // A part written by another tool, whose channels are named without the part's name.
    parts.push_back({"ViewLayer.Normal",
                     {{"X", plane(9.0f)}, {"Y", plane(10.0f)}, {"Z", plane(11.0f)}}});
    write_multipart(path, parts, {{"glslppm.passes", "7"}});
    const ExrChannels back = read_exr_file(path);
    std::remove(path.c_str());
    EXPECT_EQ(back.width, kWidth);
    EXPECT_EQ(back.height, kHeight);
    EXPECT_TRUE(back.multilayer);
    EXPECT_EQ(back.attributes.at("glslppm.passes"), "7");
    std::map<std::string, std::vector<float>> expected;
    for (const Part& part : parts)
        for (const auto& [channel, values] : part.channels)
            expected[channel.find('.') == std::string::npos ? part.name + "." + channel
                                                            : channel] = values;
    ASSERT_EQ(back.channels.size(), 11u);
    EXPECT_EQ(back.channels, expected);  // bit for bit
}

TEST(ExrMultiPart, FarmMergeKeepsEveryPass) {
    // Job a: one pass of the values x1; job b: three passes of x5; the merge is their mean
    // weighted by passes, (1 + 15) / 4 = 4 times the values, in every pass of every part.
    const std::string dir = ::testing::TempDir();
    const std::string a = dir + "exr_multipart_a.exr", b = dir + "exr_multipart_b.exr",
                      out = dir + "exr_multipart_merged.exr";
    const std::map<std::string, std::string> common = {{"glslppm.estimator", "pppm"},
                                                       {"glslppm.seed", "0"},
                                                       {"glslppm.settings", "width=3;height=2"},
                                                       {"glslppm.scene_hash", "abc"}};
    auto attributes = [&](const std::string& ranges, const std::string& passes) {
        auto all = common;
        all["glslppm.pass_ranges"] = ranges;
        all["glslppm.passes"] = passes;
        return all;
    };
    write_multipart(a, blender5_parts(1.0f), attributes("0-1", "1"));
    write_multipart(b, blender5_parts(5.0f), attributes("1-4", "3"));
    const auto merged_attributes = merge_farm_files({b, a}, out);
    const ExrChannels merged = read_exr_file(out);
    for (const std::string& path : {a, b, out}) std::remove(path.c_str());
    EXPECT_EQ(merged_attributes.at("glslppm.pass_ranges"), "0-4");
    EXPECT_TRUE(merged.multilayer);
    const std::vector<Part> four = blender5_parts(4.0f);
    std::size_t count = 0;
    for (const Part& part : four)
        for (const auto& [channel, values] : part.channels) {
            ASSERT_TRUE(merged.channels.count(channel)) << channel;
            const std::vector<float>& got = merged.channels.at(channel);
            for (std::size_t i = 0; i < values.size(); ++i)
                // (1 x v1 + 3 x v5) / 4, against the expected value rounded in float: a few
                // 2^-24 apart (MERGE_BOUND of tests/blender/test_farm.py).
                EXPECT_NEAR(got[i], values[i], 1e-6f * std::abs(values[i])) << channel << i;
            ++count;
        }
    EXPECT_EQ(merged.channels.size(), count);  // 8 channels, none dropped
}

}  // namespace
}  // namespace glslppm
