// The GLB container: what the builder writes parses back (chunks, alignment, accessors), and
// damaged files are refused with a reason.
#include "gltf/glb.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace glint::gltf {
namespace {

TEST(Glb, BuilderOutputParsesBackWithAlignedChunksAndAccessors) {
  GlbBuilder builder;
  const std::vector<std::uint8_t> odd{1, 2, 3};  // forces padding before the next view
  const int image = builder.add_buffer_view(odd);
  const std::vector<float> positions{0, 0, 0, 1, 2, 3, -1, 5, 0.5f};
  const int position = builder.add_float_accessor(positions, 3, true);
  const std::vector<std::uint32_t> indices{0, 1, 2};
  const int index = builder.add_index_accessor(indices);
  const std::vector<std::uint8_t> bytes = builder.bytes();
  ASSERT_EQ(bytes.size() % 4, 0u);
  const Glb glb = parse_glb(bytes, "memory");
  EXPECT_EQ(glb.document["asset"]["version"], "2.0");
  EXPECT_EQ(glb.document["bufferViews"][image]["byteLength"], 3);
  const nlohmann::json& view = glb.document["bufferViews"][1];
  EXPECT_EQ(int(view["byteOffset"]) % 4, 0);
  EXPECT_EQ(view["target"], kArrayBuffer);
  EXPECT_EQ(glb.document["accessors"][position]["min"], nlohmann::json({-1, 0, 0}));
  EXPECT_EQ(glb.document["accessors"][position]["max"], nlohmann::json({1, 5, 3}));
  const std::vector<double> read = accessor_values(glb, position);
  ASSERT_EQ(read.size(), positions.size());
  for (std::size_t i = 0; i < read.size(); ++i) EXPECT_EQ(read[i], positions[i]);
  EXPECT_EQ(accessor_values(glb, index), (std::vector<double>{0, 1, 2}));
  EXPECT_EQ(glb.document["buffers"][0]["byteLength"], glb.bin.size());
}

TEST(Glb, DamagedFilesAreRefused) {
  GlbBuilder builder;
  builder.add_float_accessor(std::vector<float>{1, 2, 3}, 3);
  std::vector<std::uint8_t> bytes = builder.bytes();
  std::vector<std::uint8_t> truncated(bytes.begin(), bytes.end() - 8);
  EXPECT_THROW(parse_glb(truncated, "t.glb"), Error);
  std::vector<std::uint8_t> magic = bytes;
  magic[0] = 'x';
  EXPECT_THROW(parse_glb(magic, "m.glb"), Error);
  std::vector<std::uint8_t> json = bytes;
  json[20] = '#';  // the JSON chunk's first character
  EXPECT_THROW(parse_glb(json, "j.glb"), Error);
  EXPECT_THROW(builder.add_float_accessor(std::vector<float>{1, 2}, 3), Error);
}

}  // namespace
}  // namespace glint::gltf
