#include "io/text_cloud.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/error.h"
#include "io_test_support.h"

namespace glint::io {
namespace {

using test::error_of;
using test::fixture;
using test::scratch;
using test::write_text;
using ::testing::HasSubstr;

TEST(TextCloud, HeaderNamesColumnsAndCommentsAndBlankLinesAreSkipped) {
  const PointCloud cloud = read_text_cloud(fixture("labelled.xyz"));
  ASSERT_EQ(cloud.size(), 4u);
  EXPECT_EQ(cloud.x, (std::vector<float>{0, 1, 0, 0}));
  EXPECT_EQ(cloud.y, (std::vector<float>{0, 0, 1, 0}));
  EXPECT_EQ(cloud.z, (std::vector<float>{0, 0, 0, 1}));
  ASSERT_EQ(cloud.attributes().size(), 1u);
  EXPECT_EQ(*cloud.get<float>("label"), (std::vector<float>{0, 1, 2, 1}));
}

TEST(TextCloud, PtsCountLineIsCheckedAndAnIntegerFourthColumnIsALabel) {
  const PointCloud cloud = read_text_cloud(fixture("count_first.pts"));
  ASSERT_EQ(cloud.size(), 3u);
  EXPECT_EQ(cloud.x, (std::vector<float>{0.5f, 1, 2}));
  EXPECT_EQ(*cloud.get<float>("label"), (std::vector<float>{10, 20, 30}));

  const std::string path = scratch("wrong_count.pts");
  write_text(path, "5\n0 0 0\n1 1 1\n");
  const Error e = error_of([&] { read_text_cloud(path); });
  EXPECT_EQ(e.element(), "line 1");
  EXPECT_EQ(e.reason(), "announces 5 points, the file holds 2");
}

TEST(TextCloud, UnnamedColumnsAreNumberedAndNamedOnesKeepTheirNames) {
  const std::string path = scratch("columns.txt");
  write_text(path, "1,2,3,0.5,7\n4,5,6,0.25,8\n");
  const PointCloud numbered = read_text_cloud(path);
  EXPECT_EQ(*numbered.get<float>("column3"), (std::vector<float>{0.5f, 0.25f}));
  EXPECT_EQ(*numbered.get<float>("column4"), (std::vector<float>{7, 8}));

  write_text(path, "1 2 3 0.5\n");
  EXPECT_TRUE(read_text_cloud(path).has("column3"));  // not whole: not a label

  write_text(path, "X,Y,Z,Intensity\n1,2,3,0.5\n");
  EXPECT_EQ(*read_text_cloud(path).get<float>("Intensity"), (std::vector<float>{0.5f}));
}

TEST(TextCloud, TabsAndSignsAndScientificNotation) {
  const std::string path = scratch("signs.xyz");
  write_text(path, "+1\t-2e1\t3.5E-1\n");
  const PointCloud cloud = read_text_cloud(path);
  EXPECT_EQ(cloud.x[0], 1);
  EXPECT_EQ(cloud.y[0], -20);
  EXPECT_EQ(cloud.z[0], 0.35f);
}

void expect_text_error(const std::string& text, const std::string& element,
                       const std::string& reason) {
  const std::string path = scratch("bad.xyz");
  write_text(path, text);
  const Error e = error_of([&] { read_text_cloud(path); });
  EXPECT_EQ(e.file(), path);
  EXPECT_EQ(e.element(), element) << e.what();
  EXPECT_THAT(e.reason(), HasSubstr(reason));
}

TEST(TextCloud, MalformedRowsNameTheLine) {
  expect_text_error("0 0 0\n1 1 1\n2 2\n", "line 3", "expected 3 columns (as on line 1), found 2");
  expect_text_error("# header\n0 0 0 1\n1 1 1 1 1\n", "line 3", "expected 4 columns");
  expect_text_error("0 0 0\n1 x 1\n", "line 2", "not a number: 'x'");
  expect_text_error("0 0 0\n1 inf 1\n", "line 2", "non-finite coordinate");
  expect_text_error("0 0 0\nnan 1 1\n", "line 2", "non-finite coordinate");
  expect_text_error("0 0\n", "line 1", "need at least 3 columns");
  expect_text_error("//x y z label\n0 0 0\n", "line 2",
                    "the header names 4 columns, the row has 3");
  expect_text_error("0 0 0 1e300\n", "line 1", "outside the float range");
}

TEST(TextCloud, OnlyCommentsIsAnEmptyCloud) {
  const std::string path = scratch("comments.xyz");
  write_text(path, "# nothing\n// here\n\n");
  EXPECT_TRUE(read_text_cloud(path).empty());
}

TEST(TextCloud, RoundTripKeepsValuesAndNames) {
  PointCloud cloud;
  cloud.push_back(0.1f, 0.2f, 0.3f);
  cloud.push_back(-1e-5f, 1e5f, 3.3333333f);
  cloud.set("label", std::vector<std::uint8_t>{1, 2});
  cloud.set("weight", std::vector<float>{0.1f, 1e-30f});
  const std::string path = scratch("round_trip.xyz");
  write_text_cloud(path, cloud);
  EXPECT_EQ(test::read_text(path).substr(0, 22), "//x y z label weight\n0");
  const PointCloud back = read_text_cloud(path);
  EXPECT_EQ(back.x, cloud.x);
  EXPECT_EQ(back.y, cloud.y);
  EXPECT_EQ(back.z, cloud.z);
  EXPECT_EQ(*back.get<float>("label"), (std::vector<float>{1, 2}));
  EXPECT_EQ(*back.get<float>("weight"), (std::vector<float>{0.1f, 1e-30f}));
}

TEST(TextCloud, MissingFileIsAnError) {
  EXPECT_THAT(error_of([] { read_text_cloud(scratch("missing.xyz")); }).reason(),
              HasSubstr("cannot open the file"));
}

}  // namespace
}  // namespace glint::io
