// Line plots as PNG: image size, where a series is drawn, gaps, and invalid figures.
#include "io/plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "io_test_support.h"

namespace glint::io {
namespace {

PlotSeries constant_series(double value, std::size_t n, std::array<std::uint8_t, 3> rgb) {
  PlotSeries series;
  series.name = "constant";
  series.rgb = rgb;
  series.line_width_px = 3;
  series.values.assign(n, value);
  return series;
}

// Pixel (x, y) of a BGR image as RGB.
std::array<int, 3> rgb_at(const cv::Mat& image, int x, int y) {
  const cv::Vec3b bgr = image.at<cv::Vec3b>(y, x);
  return {bgr[2], bgr[1], bgr[0]};
}

TEST(Plot, DrawsAConstantSeriesAtItsValue) {
  PlotFigure figure;
  figure.title = "kd over time";
  PlotPanel kd;
  kd.title = "diffuse albedo";
  kd.y_label = "kd";
  kd.y_range = {{0.0, 1.0}};
  kd.series.push_back(constant_series(0.25, 50, {200, 30, 40}));
  PlotPanel alpha;
  alpha.title = "roughness";
  alpha.y_range = {{0.0, 0.5}};
  alpha.series.push_back(constant_series(0.4, 50, {20, 160, 60}));
  alpha.series.back().dashed = true;
  figure.panels = {kd, alpha};

  const std::string path = test::scratch("plot.png");
  write_line_plot_png(path, figure);
  const cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 1200);
  EXPECT_EQ(image.rows, plot_height_px(figure));
  EXPECT_GE(image.rows, 2 * 220);

  const PixelRect top = plot_area(figure, 0);
  const int x = top.x + top.width / 3;
  const int y = top.y + int(std::lround(0.75 * (top.height - 1)));  // 0.25 of [0, 1], bottom-up
  EXPECT_EQ(rgb_at(image, x, y), (std::array<int, 3>{200, 30, 40}));
  EXPECT_EQ(rgb_at(image, x, top.y + top.height / 4), (std::array<int, 3>{255, 255, 255}));

  // The dashed series: its colour on the row, white between the dashes.
  const PixelRect bottom = plot_area(figure, 1);
  EXPECT_GT(bottom.y, top.y + top.height);
  const int row = bottom.y + int(std::lround(0.2 * (bottom.height - 1)));
  int coloured = 0, blank = 0;
  for (int c = bottom.x + 5; c < bottom.x + bottom.width - 5; ++c) {
    const std::array<int, 3> pixel = rgb_at(image, c, row);
    coloured += pixel == std::array<int, 3>{20, 160, 60};
    blank += pixel[0] > 200 && pixel[1] > 200 && pixel[2] > 200;
  }
  EXPECT_GT(coloured, bottom.width / 3);
  EXPECT_GT(blank, bottom.width / 10);
}

TEST(Plot, GapsBreakTheLine) {
  PlotFigure figure;
  PlotPanel panel;
  panel.y_range = {{0.0, 1.0}};
  PlotSeries series = constant_series(0.5, 101, {0, 0, 255});
  for (std::size_t i = 40; i < 60; ++i) series.values[i] = NAN;
  series.values[80] = INFINITY;
  series.values[100] = NAN;
  series.values[98] = NAN;  // 99 is an isolated sample: a dot
  panel.series.push_back(series);
  figure.panels.push_back(panel);
  const std::string path = test::scratch("gaps.png");
  write_line_plot_png(path, figure);
  const cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
  const PixelRect area = plot_area(figure, 0);
  const int row = area.y + int(std::lround(0.5 * (area.height - 1)));
  auto column_of = [&](double i) { return area.x + int(std::lround(i / 100 * (area.width - 1))); };
  EXPECT_EQ(rgb_at(image, column_of(20), row), (std::array<int, 3>{0, 0, 255}));
  EXPECT_EQ(rgb_at(image, column_of(45), row), (std::array<int, 3>{255, 255, 255}));
  EXPECT_EQ(rgb_at(image, column_of(70), row), (std::array<int, 3>{0, 0, 255}));
  EXPECT_EQ(rgb_at(image, column_of(99), row), (std::array<int, 3>{0, 0, 255}));
}

TEST(Plot, DataRangeAndManyLegendEntriesAreLaidOut) {
  PlotFigure figure;
  figure.width_px = 400;
  PlotPanel panel;
  for (int s = 0; s < 4; ++s) {
    PlotSeries series = constant_series(s, 10, {uint8_t(30 * s), 0, 0});
    series.name = "series number " + std::to_string(s);
    panel.series.push_back(series);
  }
  figure.panels.push_back(panel);
  const PixelRect area = plot_area(figure, 0);
  EXPECT_GT(area.y, 3 * 22);  // the legend wrapped onto several header rows
  const std::string path = test::scratch("legend.png");
  write_line_plot_png(path, figure);
  EXPECT_EQ(cv::imread(path).cols, 400);
}

TEST(Plot, InvalidFiguresAreErrorsNamingTheFile) {
  const std::string path = test::scratch("bad.png");
  EXPECT_EQ(test::error_of([&] { write_line_plot_png(path, PlotFigure{}); }).file(), path);
  PlotFigure all_gaps;
  all_gaps.panels.resize(1);
  all_gaps.panels[0].series.push_back(constant_series(NAN, 10, {0, 0, 0}));
  EXPECT_THROW(write_line_plot_png(path, all_gaps), Error);
  PlotFigure bad_range;
  bad_range.panels.resize(1);
  bad_range.panels[0].y_range = {{1.0, 1.0}};
  bad_range.panels[0].series.push_back(constant_series(1, 10, {0, 0, 0}));
  EXPECT_EQ(test::error_of([&] { write_line_plot_png(path, bad_range); }).element(),
            "panels[0].y_range");
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace glint::io
