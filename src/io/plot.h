#pragma once
// Line plots of per-frame values as PNG (e.g. estimated vs ground-truth material parameters over
// a sequence, paper 1 Fig. 4): vertically stacked panels sharing one x axis, drawn with OpenCV
// (anti-aliased lines, Hershey font) on a white background.
//
// Layout, top to bottom: the figure title (when set), then per panel a header row (title on the
// left, legend entries on the right, wrapping onto more rows when they do not fit) above the
// panel's plot area, y ticks and the y label on the left; below the last panel the x tick labels
// and the x label. Sample i of every series sits at x = x_start + i * x_step.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace glint::io {

struct PlotSeries {
  std::string name;  // legend entry; empty: not in the legend
  std::array<std::uint8_t, 3> rgb{31, 119, 180};
  int line_width_px = 2;
  bool dashed = false;
  std::vector<double> values;  // one per x; NaN (or inf) is a gap: the line breaks there
};

struct PlotPanel {
  std::string title;
  std::string y_label;
  std::optional<std::pair<double, double>> y_range;  // fixed (lower, upper); else the data's
  std::vector<PlotSeries> series;
};

struct PlotFigure {
  std::string title;
  std::string x_label = "frame";
  double x_start = 0, x_step = 1;
  std::vector<PlotPanel> panels;
  int width_px = 1200;
  int panel_height_px = 220;  // header row(s) included
};

// A rectangle in image pixels (x, y: top-left corner).
struct PixelRect {
  int x = 0, y = 0, width = 0, height = 0;
};

// Where panel `panel`'s plot area lies in the image write_line_plot_png writes; the image is
// figure.width_px wide and plot_height_px(figure) high. The y axis maps the range bottom-up
// onto the area's rows, the x range [x_start, x_start + (n - 1) x_step] (n: the longest series)
// onto its columns. Throws glint::Error for an invalid figure (see below).
PixelRect plot_area(const PlotFigure& figure, std::size_t panel);
int plot_height_px(const PlotFigure& figure);

// Writes the figure as an 8-bit RGB PNG, atomically. Throws glint::Error naming `path` for a
// figure without panels or without any finite value, width_px < 300, panel_height_px < 100, an
// empty or non-finite y_range, or a line width outside [1, 20]; or when the file cannot be
// written.
void write_line_plot_png(const std::string& path, const PlotFigure& figure);

}  // namespace glint::io
