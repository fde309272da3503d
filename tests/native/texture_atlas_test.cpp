// pack_textures (render/texture_atlas.h) without a GPU: one image under several wraps and uv
// maps is packed once, each texture keeping its own wrap and uv map in its record.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <tuple>

#include "render/texture_atlas.h"

namespace glslppm {
namespace {

Texture checker(int size, float value) {
    Texture t;
    t.name = "checker";
    t.width = t.height = size;
    t.linear.assign(std::size_t(size) * size * 4, value);
    return t;
}

TEST(TextureAtlas, SamePixelsShareOneRectangleWithTheirOwnWrapAndUvMap) {
    Texture a = checker(64, 0.5f);
    Texture b = a;  // the same image, tiled 3 times and mirrored
    b.wrap = TextureWrap::Mirror;
    b.uv_map_u = {3.0f, 0.0f, 0.25f};
    b.uv_map_v = {0.0f, 3.0f, -0.5f};
    Texture c = checker(64, 0.25f);  // another image of the same size
    const TextureAtlas atlas = pack_textures({a, b, c}, {true, true, true}, 4096, 16);
    const AtlasPlacement& pa = atlas.placements[0];
    const AtlasPlacement& pb = atlas.placements[1];
    const AtlasPlacement& pc = atlas.placements[2];
    EXPECT_EQ(std::tie(pa.layer, pa.x, pa.y), std::tie(pb.layer, pb.x, pb.y));
    EXPECT_NE(std::tie(pa.layer, pa.x, pa.y), std::tie(pc.layer, pc.x, pc.y));
    // Two images' pixels in the layers, not three.
    std::size_t nonzero = 0;
    for (float v : atlas.linear) nonzero += v != 0.0f;
    EXPECT_EQ(nonzero, 2u * 64 * 64 * 4);
    const std::vector<GpuTexture> records = atlas.records();
    ASSERT_EQ(records.size(), 3u);
    EXPECT_EQ(records[0].info.z, static_cast<int>(TextureWrap::Repeat));
    EXPECT_EQ(records[1].info.z, static_cast<int>(TextureWrap::Mirror));
    EXPECT_EQ(records[0].uv_map_u, glm::vec4(1.0f, 0.0f, 0.0f, 0.0f));
    EXPECT_EQ(records[1].uv_map_u, glm::vec4(3.0f, 0.0f, 0.25f, 0.0f));
    EXPECT_EQ(records[1].uv_map_v, glm::vec4(0.0f, 3.0f, -0.5f, 0.0f));
}

TEST(TextureAtlas, InterpolationSitsAboveTheWrapAndSharesThePixels) {
    Texture a = checker(8, 0.5f);
    a.wrap = TextureWrap::Extend;
    Texture b = a;  // the same image read Closest
    b.interpolation = TextureInterpolation::Closest;
    const TextureAtlas atlas = pack_textures({a, b}, {true, true}, 4096, 16);
    EXPECT_EQ(std::tie(atlas.placements[0].x, atlas.placements[0].y),
              std::tie(atlas.placements[1].x, atlas.placements[1].y));
    const std::vector<GpuTexture> records = atlas.records();
    ASSERT_EQ(records.size(), 2u);
    // Linear: the wrap alone, as before interpolation was carried.
    EXPECT_EQ(records[0].info.z, WRAP_EXTEND);
    EXPECT_EQ(records[1].info.z,
              WRAP_EXTEND | INTERPOLATION_CLOSEST << TEXTURE_INTERPOLATION_SHIFT);
    EXPECT_EQ(records[1].info.z & TEXTURE_WRAP_MASK, WRAP_EXTEND);
}

TEST(TextureAtlas, UvMapThatIsNotFiniteIsAnErrorNamingTheTexture) {
    Texture a = checker(4, 1.0f);
    a.uv_map_v.z = std::numeric_limits<float>::quiet_NaN();
    try {
        pack_textures({a}, {true}, 4096, 16);
        FAIL() << "no error";
    } catch (const SceneError& e) {
        EXPECT_NE(std::string(e.what()).find("'checker': its uv map holds NaN"), std::string::npos)
            << e.what();
    }
}

}  // namespace
}  // namespace glslppm
