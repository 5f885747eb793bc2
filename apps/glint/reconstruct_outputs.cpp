#include "reconstruct_outputs.h"

#include <fmt/format.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "io/image_io.h"
#include "io/plot.h"
#include "render/sensor.h"

namespace glint::app {
namespace {

namespace fs = std::filesystem;

ImageF srgb_picture(const ImageF& linear) {
  ImageF picture = linear;
  for (float& v : picture.values()) v = render::linear_to_srgb(std::clamp(v, 0.0f, 1.0f));
  return picture;
}

// A distinct colour per segment id (golden-ratio hue steps), black for 0.
Eigen::Vector3f segment_colour(int id) {
  if (id <= 0) return Eigen::Vector3f::Zero();
  const float hue = std::fmod(id * 0.618034f, 1.0f) * 6.0f;
  const float f = hue - std::floor(hue);
  const std::array<Eigen::Vector3f, 6> sextants{
      Eigen::Vector3f(1, f, 0),     Eigen::Vector3f(1 - f, 1, 0), Eigen::Vector3f(0, 1, f),
      Eigen::Vector3f(0, 1 - f, 1), Eigen::Vector3f(f, 0, 1),     Eigen::Vector3f(1, 0, 1 - f)};
  return 0.15f + 0.85f * sextants[int(hue) % 6].array();
}

}  // namespace

void write_view_pictures(const std::string& folder, int index,
                         const reflectance::MaterialMaps& maps) {
  const std::string stem = (fs::path(folder) / fmt::format("{:06d}", index)).string();
  io::write_image(stem + "-render.png", srgb_picture(maps.rgb_refined));
  io::write_image(stem + "-render-hemicnn.png", srgb_picture(maps.rgb));
  io::write_image(stem + "-albedo.png", srgb_picture(maps.kd_refined));
}

void write_frame_pictures(const std::string& output, int frame, const ImageF& input_colour,
                          const reflectance::MaterialMaps& maps) {
  const std::string folder = (fs::path(output) / "frames").string();
  write_view_pictures(folder, frame, maps);
  const std::string stem = (fs::path(folder) / fmt::format("{:06d}", frame)).string();
  const ImageF input = srgb_picture(input_colour);
  io::write_image(stem + "-input.png", input);
  ImageF segments(maps.segment.width(), maps.segment.height(), 3);
  for (int y = 0; y < segments.height(); ++y)
    for (int x = 0; x < segments.width(); ++x) {
      const Eigen::Vector3f colour = segment_colour(maps.segment.at(x, y, 0));
      for (int c = 0; c < 3; ++c) segments.at(x, y, c) = colour[c];
    }
  io::write_image(stem + "-segments.png", segments);
  // One picture to look at: input | re-rendering | refined albedo | segments.
  const ImageF render = srgb_picture(maps.rgb_refined), albedo = srgb_picture(maps.kd_refined);
  const std::array<const ImageF*, 4> row{&input, &render, &albedo, &segments};
  const int width = input.width(), height = input.height();
  ImageF overview(4 * width, height, 3);
  for (int k = 0; k < 4; ++k)
    for (int c = 0; c < 3; ++c)
      for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) overview.at(k * width + x, y, c) = row[k]->at(x, y, c);
  io::write_image(stem + "-overview.png", overview);
}

void write_material_plots(const std::string& path,
                          const reflectance::MaterialEvaluation& evaluation, int frame_step) {
  using Sample = reflectance::MaterialEvaluation::Sample;
  int last_frame = 0;
  for (const auto& [object, samples] : evaluation.series())
    for (const Sample& s : samples) last_frame = std::max(last_frame, s.frame);
  const std::size_t slots = std::size_t(last_frame / frame_step) + 1;
  io::PlotFigure figure;
  figure.title = "Estimated (thin), refined (dashed) and true (bold) parameters per object";
  figure.x_step = frame_step;
  struct Row {
    const char* title;
    const char* label;
    double Sample::*estimate;
    double Sample::*refined;  // nullptr: none
    double Sample::*truth;
  };
  const std::array<Row, 4> rows{
      Row{"diffuse albedo kd (red)", "kd_r", &Sample::kd, &Sample::kd_refined, &Sample::true_kd},
      Row{"specular albedo ks (red)", "ks_r", &Sample::ks, nullptr, &Sample::true_ks},
      Row{"roughness alpha", "alpha", &Sample::alpha, nullptr, &Sample::true_alpha},
      Row{"rendered RGB (red, sRGB)", "R", &Sample::rgb, &Sample::rgb_refined, &Sample::true_rgb}};
  for (const Row& row : rows) {
    io::PlotPanel& panel = figure.panels.emplace_back();
    panel.title = row.title;
    panel.y_label = row.label;
    for (const auto& [object, object_samples] : evaluation.series()) {
      // clang 14 (the fuzz and sanitizer builds) cannot capture a structured binding in a lambda.
      const auto& samples = object_samples;
      const Eigen::Vector3f colour = segment_colour(object) * 0.85f;
      const std::array<std::uint8_t, 3> rgb{std::uint8_t(colour.x() * 255),
                                            std::uint8_t(colour.y() * 255),
                                            std::uint8_t(colour.z() * 255)};
      const auto series = [&](double Sample::*member, const std::string& name, int width,
                              bool dashed) {
        io::PlotSeries s{name, rgb, width, dashed, std::vector<double>(slots, NAN)};
        for (const Sample& sample : samples) s.values[sample.frame / frame_step] = sample.*member;
        panel.series.push_back(std::move(s));
      };
      series(row.truth, fmt::format("object {}", object), 4, false);
      series(row.estimate, "", 1, false);
      if (row.refined) series(row.refined, "", 1, true);
    }
  }
  io::write_line_plot_png(path, figure);
}

void print_evaluation_table(const reflectance::MaterialEvaluation& evaluation) {
  const auto table = evaluation.table();
  const auto average = evaluation.average();
  using reflectance::Scores;
  const std::array<std::pair<const char*, double Scores::*>, 4> metrics{
      std::pair{"L1", &Scores::l1}, std::pair{"RMSE", &Scores::rmse},
      std::pair{"PSNR", &Scores::psnr}, std::pair{"SSIM", &Scores::ssim}};
  for (const auto& [metric_name, metric] : metrics) {
    std::string header = fmt::format("{:<8}", metric_name);
    for (const auto& [object, scores] : table)
      header += fmt::format("{:>8}", fmt::format("S{}", object));
    header += fmt::format("{:>8}", "avg");
    std::printf("%s\n", header.c_str());
    for (reflectance::Quantity quantity : reflectance::kQuantities) {
      std::string line = fmt::format("{:<8}", reflectance::quantity_name(quantity));
      for (const auto& [object, scores] : table)
        line += fmt::format("{:>8.3f}", scores.at(quantity).*metric);
      line += fmt::format("{:>8.3f}", average.at(quantity).*metric);
      std::printf("%s\n", line.c_str());
    }
  }
}

}  // namespace glint::app
