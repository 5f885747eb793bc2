#include "core/point_cloud.h"

#include <gtest/gtest.h>

#include "core/error.h"

namespace glint {
namespace {

TEST(PointCloud, TypedAttributesFollowThePoints) {
  PointCloud cloud;
  cloud.push_back(0, 0, 0);
  cloud.push_back(1, 2, 3);
  cloud.push_back(4, 5, 6);
  cloud.set("label", std::vector<std::uint8_t>{0, 1, 2});
  cloud.set("weight", std::vector<double>{0.5, 1.5, 2.5});
  ASSERT_NE(cloud.get<std::uint8_t>("label"), nullptr);
  EXPECT_EQ(cloud.get<float>("label"), nullptr);  // wrong type
  EXPECT_EQ(column_value(*cloud.find("weight"), 2), 2.5);

  const PointCloud kept = cloud.select({true, false, true});
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(kept.x[1], 4.f);
  EXPECT_EQ((*kept.get<std::uint8_t>("label"))[1], 2);
  EXPECT_EQ(kept.attributes().size(), 2u);

  cloud.remove("weight");
  EXPECT_FALSE(cloud.has("weight"));
}

TEST(PointCloud, RejectsWrongLengths) {
  PointCloud cloud;
  cloud.push_back(0, 0, 0);
  EXPECT_THROW(cloud.set("label", std::vector<std::uint8_t>{1, 2}), Error);
  EXPECT_THROW(cloud.select({true, true}), Error);
}

TEST(Error, MessageNamesFileElementAndReason) {
  const Error e("cloud.ply", "vertex 12", "non-finite coordinate");
  EXPECT_STREQ(e.what(), "cloud.ply: vertex 12: non-finite coordinate");
  EXPECT_EQ(e.file(), "cloud.ply");
  EXPECT_EQ(Error("", "", "plain").what(), std::string("plain"));
}

}  // namespace
}  // namespace glint
