#include "io/plot.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "io/atomic_file.h"

namespace glint::io {
namespace {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kLabelScale = 0.45, kTitleScale = 0.52, kFigureTitleScale = 0.62;
constexpr int kMarginLeft = 92, kMarginRight = 24, kMarginBottom = 52, kFigureTitleHeight = 34;
constexpr int kTopPadding = 8, kHeaderRowHeight = 22, kPanelGap = 12;
constexpr int kLegendSample = 40, kLegendGap = 18;  // sample line length, space between entries
constexpr int kMinPlotHeight = 40;                  // rows of a plot area at least
const cv::Scalar kBlack(0, 0, 0), kAxis(70, 70, 70), kGrid(228, 228, 228), kWhite(255, 255, 255);

int text_width(const std::string& text, double scale) {
  int baseline = 0;
  return cv::getTextSize(text, kFont, scale, 1, &baseline).width;
}

cv::Scalar bgr(const std::array<std::uint8_t, 3>& rgb) {
  return {double(rgb[2]), double(rgb[1]), double(rgb[0])};
}

void validate(const PlotFigure& figure, const std::string& name) {
  if (figure.panels.empty()) throw Error(name, "", "the figure has no panels");
  if (figure.width_px < 300) throw Error(name, "width_px", "must be >= 300");
  if (figure.panel_height_px < 100) throw Error(name, "panel_height_px", "must be >= 100");
  if (!(figure.x_step > 0) || !std::isfinite(figure.x_step) || !std::isfinite(figure.x_start))
    throw Error(name, "x_step", "x_start must be finite and x_step > 0");
  bool any_value = false;
  for (std::size_t p = 0; p < figure.panels.size(); ++p) {
    const PlotPanel& panel = figure.panels[p];
    if (panel.y_range &&
        !(std::isfinite(panel.y_range->first) && std::isfinite(panel.y_range->second) &&
          panel.y_range->first < panel.y_range->second))
      throw Error(name, fmt::format("panels[{}].y_range", p), "must be finite with lower < upper");
    for (std::size_t s = 0; s < panel.series.size(); ++s) {
      const PlotSeries& series = panel.series[s];
      if (series.line_width_px < 1 || series.line_width_px > 20)
        throw Error(name, fmt::format("panels[{}].series[{}].line_width_px", p, s),
                    "must be in [1, 20]");
      any_value = any_value || std::any_of(series.values.begin(), series.values.end(),
                                           [](double v) { return std::isfinite(v); });
    }
  }
  if (!any_value) throw Error(name, "", "the figure has no finite value to plot");
}

// Legend entries of a panel packed into rows; row 0 shares its line with the panel title.
struct LegendRow {
  std::vector<std::size_t> entries;
  int width = 0;
};

int legend_entry_width(const PlotSeries& series) {
  return kLegendSample + 6 + text_width(series.name, kLabelScale);
}

std::vector<LegendRow> legend_rows(const PlotPanel& panel, int plot_width) {
  const int first_row_width =
      plot_width -
      (panel.title.empty() ? 0 : text_width(panel.title, kTitleScale) + 2 * kLegendGap);
  std::vector<LegendRow> rows(1);
  for (std::size_t s = 0; s < panel.series.size(); ++s) {
    if (panel.series[s].name.empty()) continue;
    const int width = legend_entry_width(panel.series[s]);
    const int available = rows.size() == 1 ? first_row_width : plot_width;
    LegendRow& row = rows.back();
    const int needed = row.entries.empty() ? width : row.width + kLegendGap + width;
    if (needed <= available || (row.entries.empty() && rows.size() > 1)) {
      row.entries.push_back(s);
      row.width = needed;
    } else {
      rows.push_back({{s}, width});
    }
  }
  return rows;
}

int top_margin(const PlotFigure& figure) {
  return figure.title.empty() ? kTopPadding : kFigureTitleHeight;
}

PixelRect area_of(const PlotFigure& figure, std::size_t panel, const std::string& name) {
  const int plot_width = figure.width_px - kMarginLeft - kMarginRight;
  const int header_rows = int(legend_rows(figure.panels[panel], plot_width).size());
  const int panel_top = top_margin(figure) + int(panel) * figure.panel_height_px;
  const int header = header_rows * kHeaderRowHeight + 4;
  const int height = figure.panel_height_px - header - kPanelGap;
  if (height < kMinPlotHeight)
    throw Error(name, fmt::format("panels[{}]", panel),
                "its legend does not fit the panel height; raise panel_height_px");
  return {kMarginLeft, panel_top + header, plot_width, height};
}

struct Range {
  double lower = 0, upper = 1;
};

Range y_range_of(const PlotPanel& panel) {
  if (panel.y_range) return {panel.y_range->first, panel.y_range->second};
  double lower = INFINITY, upper = -INFINITY;
  for (const PlotSeries& series : panel.series)
    for (double v : series.values)
      if (std::isfinite(v)) {
        lower = std::min(lower, v);
        upper = std::max(upper, v);
      }
  if (!std::isfinite(lower)) return {0, 1};  // a panel without values: empty axes
  const double pad = upper > lower ? 0.05 * (upper - lower) : std::max(0.5, 0.1 * std::abs(upper));
  return {lower - pad, upper + pad};
}

// Ticks at 1, 2 or 5 times a power of ten, about `target` of them inside the range.
std::vector<double> nice_ticks(const Range& range, int target, double* step_out) {
  const double raw = (range.upper - range.lower) / std::max(1, target);
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  const double fraction = raw / power;
  const double step = (fraction < 1.5 ? 1 : fraction < 3 ? 2 : fraction < 7 ? 5 : 10) * power;
  std::vector<double> ticks;
  for (double t = std::ceil(range.lower / step - 1e-9) * step; t <= range.upper + 1e-9 * step;
       t += step)
    ticks.push_back(std::abs(t) < 1e-12 * step ? 0.0 : t);
  *step_out = step;
  return ticks;
}

std::string tick_label(double value, double step) {
  const int decimals = std::max(0, -int(std::floor(std::log10(step) + 1e-9)));
  return fmt::format("{:.{}f}", value, decimals);
}

void put_text(cv::Mat& image, const std::string& text, cv::Point origin, double scale,
              const cv::Scalar& colour = kBlack) {
  cv::putText(image, text, origin, kFont, scale, colour, 1, cv::LINE_AA);
}

// Sub-pixel line: coordinates carry 4 fractional bits.
constexpr int kShift = 4;
cv::Point fixed(double x, double y) {
  return {int(std::lround(x * (1 << kShift))), int(std::lround(y * (1 << kShift)))};
}

// A polyline, solid or dashed (the dash pattern runs on across vertices).
void draw_polyline(cv::Mat& roi, const std::vector<cv::Point2d>& points, const PlotSeries& series) {
  const cv::Scalar colour = bgr(series.rgb);
  if (points.size() == 1) {
    cv::circle(roi, fixed(points[0].x, points[0].y), series.line_width_px << kShift, colour,
               cv::FILLED, cv::LINE_AA, kShift);
    return;
  }
  const double on = 4.0 * series.line_width_px + 4, off = 2.0 * series.line_width_px + 4;
  double phase = 0;  // distance into the current on+off period
  for (std::size_t i = 1; i < points.size(); ++i) {
    const cv::Point2d a = points[i - 1], b = points[i];
    if (!series.dashed) {
      cv::line(roi, fixed(a.x, a.y), fixed(b.x, b.y), colour, series.line_width_px, cv::LINE_AA,
               kShift);
      continue;
    }
    const double length = cv::norm(b - a);
    double done = 0;
    while (done < length) {
      const bool drawing = phase < on;
      const double step = std::min(length - done, drawing ? on - phase : on + off - phase);
      if (drawing) {
        const cv::Point2d from = a + (b - a) * (done / length);
        const cv::Point2d to = a + (b - a) * ((done + step) / length);
        cv::line(roi, fixed(from.x, from.y), fixed(to.x, to.y), colour, series.line_width_px,
                 cv::LINE_AA, kShift);
      }
      done += step;
      phase = std::fmod(phase + step, on + off);
    }
  }
}

void draw_series(cv::Mat& roi, const PlotSeries& series, const Range& x, const Range& y,
                 const PlotFigure& figure) {
  std::vector<cv::Point2d> run;
  auto flush = [&] {
    if (!run.empty()) draw_polyline(roi, run, series);
    run.clear();
  };
  for (std::size_t i = 0; i < series.values.size(); ++i) {
    const double v = series.values[i];
    if (!std::isfinite(v)) {
      flush();
      continue;
    }
    const double xv = figure.x_start + double(i) * figure.x_step;
    run.emplace_back((xv - x.lower) / (x.upper - x.lower) * (roi.cols - 1),
                     (y.upper - v) / (y.upper - y.lower) * (roi.rows - 1));
  }
  flush();
}

void draw_legend(cv::Mat& image, const PlotPanel& panel, const std::vector<LegendRow>& rows,
                 int panel_top, int plot_right) {
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const int baseline = panel_top + int(r) * kHeaderRowHeight + 16;
    int x = plot_right - rows[r].width;
    for (std::size_t s : rows[r].entries) {
      const PlotSeries& series = panel.series[s];
      cv::Mat sample = image(cv::Rect(x, baseline - 10, kLegendSample, 8));
      draw_polyline(sample, {{0, 3.5}, {kLegendSample - 1.0, 3.5}}, series);
      put_text(image, series.name, {x + kLegendSample + 6, baseline}, kLabelScale);
      x += legend_entry_width(series) + kLegendGap;
    }
  }
}

void draw_y_label(cv::Mat& image, const std::string& label, const PixelRect& area) {
  if (label.empty()) return;
  int baseline = 0;
  const cv::Size size = cv::getTextSize(label, kFont, kLabelScale, 1, &baseline);
  cv::Mat text(size.height + baseline + 4, size.width + 4, CV_8UC3, kWhite);
  put_text(text, label, {2, size.height + 2}, kLabelScale);
  cv::rotate(text, text, cv::ROTATE_90_COUNTERCLOCKWISE);
  const int rows = std::min(text.rows, area.height);
  const int top = area.y + (area.height - rows) / 2;
  text(cv::Rect(0, (text.rows - rows) / 2, text.cols, rows))
      .copyTo(image(cv::Rect(4, top, text.cols, rows)));
}

cv::Mat render(const PlotFigure& figure, const std::string& name) {
  validate(figure, name);
  cv::Mat image(plot_height_px(figure), figure.width_px, CV_8UC3, kWhite);
  if (!figure.title.empty())
    put_text(image, figure.title,
             {(figure.width_px - text_width(figure.title, kFigureTitleScale)) / 2, 22},
             kFigureTitleScale);

  std::size_t samples = 1;
  for (const PlotPanel& panel : figure.panels)
    for (const PlotSeries& series : panel.series) samples = std::max(samples, series.values.size());
  const Range x{figure.x_start,
                figure.x_start + double(std::max<std::size_t>(samples - 1, 1)) * figure.x_step};
  double x_step = 1;
  const std::vector<double> x_ticks =
      nice_ticks(x, std::max(2, (figure.width_px - kMarginLeft - kMarginRight) / 110), &x_step);

  for (std::size_t p = 0; p < figure.panels.size(); ++p) {
    const PlotPanel& panel = figure.panels[p];
    const PixelRect area = area_of(figure, p, name);
    const int panel_top = top_margin(figure) + int(p) * figure.panel_height_px;
    const Range y = y_range_of(panel);
    auto column = [&](double xv) {
      return area.x + int(std::lround((xv - x.lower) / (x.upper - x.lower) * (area.width - 1)));
    };
    auto row = [&](double yv) {
      return area.y + int(std::lround((y.upper - yv) / (y.upper - y.lower) * (area.height - 1)));
    };

    put_text(image, panel.title, {area.x, panel_top + 16}, kTitleScale);
    draw_legend(image, panel, legend_rows(panel, area.width), panel_top, area.x + area.width);

    double y_step = 1;
    for (double t : nice_ticks(y, std::max(2, area.height / 32), &y_step)) {
      const int r = row(t);
      cv::line(image, {area.x, r}, {area.x + area.width - 1, r}, kGrid, 1);
      cv::line(image, {area.x - 5, r}, {area.x, r}, kAxis, 1);
      const std::string label = tick_label(t, y_step);
      put_text(image, label, {area.x - 8 - text_width(label, kLabelScale), r + 5}, kLabelScale);
    }
    for (double t : x_ticks) {
      const int c = column(t);
      cv::line(image, {c, area.y}, {c, area.y + area.height - 1}, kGrid, 1);
      cv::line(image, {c, area.y + area.height}, {c, area.y + area.height + 4}, kAxis, 1);
      if (p + 1 == figure.panels.size()) {
        const std::string label = tick_label(t, x_step);
        put_text(image, label, {c - text_width(label, kLabelScale) / 2, area.y + area.height + 20},
                 kLabelScale);
      }
    }
    draw_y_label(image, panel.y_label, area);

    cv::Mat roi = image(cv::Rect(area.x, area.y, area.width, area.height));
    for (const PlotSeries& series : panel.series) draw_series(roi, series, x, y, figure);
    cv::rectangle(image, {area.x - 1, area.y - 1}, {area.x + area.width, area.y + area.height},
                  kAxis, 1);
    if (p + 1 == figure.panels.size() && !figure.x_label.empty())
      put_text(image, figure.x_label,
               {area.x + (area.width - text_width(figure.x_label, kLabelScale)) / 2,
                area.y + area.height + 42},
               kLabelScale);
  }
  return image;
}

}  // namespace

int plot_height_px(const PlotFigure& figure) {
  return top_margin(figure) + int(figure.panels.size()) * figure.panel_height_px + kMarginBottom;
}

PixelRect plot_area(const PlotFigure& figure, std::size_t panel) {
  validate(figure, "plot");
  if (panel >= figure.panels.size())
    throw Error("plot", fmt::format("panels[{}]", panel), "no such panel");
  return area_of(figure, panel, "plot");
}

void write_line_plot_png(const std::string& path, const PlotFigure& figure) {
  const cv::Mat image = render(figure, path);
  std::vector<unsigned char> encoded;
  if (!cv::imencode(".png", image, encoded)) throw Error(path, "", "PNG encoding failed");
  AtomicFile file(path);
  file.stream().write(reinterpret_cast<const char*>(encoded.data()),
                      std::streamsize(encoded.size()));
  file.commit();
}

}  // namespace glint::io
