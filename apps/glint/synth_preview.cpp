#include "synth_preview.h"

#include <algorithm>
#include <filesystem>
#include <opencv2/imgproc.hpp>

#include "core/timer.h"
#include "io/image_io.h"
#include "render/renderer.h"
#include "render/sensor.h"

namespace glint::app {
namespace {

constexpr float kAlphaWhite = 0.35f;  // the roughest alpha of the training ranges

ImageF srgb_for_display(const ImageF& linear) {
  ImageF display(linear.width(), linear.height(), linear.channels());
  for (std::size_t i = 0; i < linear.values().size(); ++i)
    display.values()[i] = render::linear_to_srgb(std::clamp(linear.values()[i], 0.0f, 1.0f));
  return display;
}

ImageF scaled_grey(const ImageF& values, float white) {
  ImageF grey(values.width(), values.height(), 1);
  for (std::size_t i = 0; i < grey.pixel_count(); ++i)
    grey.values()[i] = std::clamp(values.plane(0)[i] / white, 0.0f, 1.0f);
  return grey;
}

// Turbo colour map from the nearest to the farthest surface; no surface stays black.
ImageF false_colour_depth(const ImageF& depth_m) {
  const float* depth = depth_m.plane(0);
  float nearest = 1e30f, farthest = 0;
  for (std::size_t i = 0; i < depth_m.pixel_count(); ++i)
    if (depth[i] > 0) {
      nearest = std::min(nearest, depth[i]);
      farthest = std::max(farthest, depth[i]);
    }
  cv::Mat grey(depth_m.height(), depth_m.width(), CV_8UC1, cv::Scalar(0));
  const float range = std::max(farthest - nearest, 1e-6f);
  for (int y = 0; y < depth_m.height(); ++y)
    for (int x = 0; x < depth_m.width(); ++x) {
      const float z = depth_m.at(x, y, 0);
      if (z > 0)
        grey.at<std::uint8_t>(y, x) = cv::saturate_cast<std::uint8_t>(255 * (z - nearest) / range);
    }
  cv::Mat colour;
  cv::applyColorMap(grey, colour, cv::COLORMAP_TURBO);
  ImageF result(depth_m.width(), depth_m.height(), 3);
  for (int y = 0; y < depth_m.height(); ++y)
    for (int x = 0; x < depth_m.width(); ++x) {
      if (!(depth_m.at(x, y, 0) > 0)) continue;
      const cv::Vec3b bgr = colour.at<cv::Vec3b>(y, x);
      for (int c = 0; c < 3; ++c) result.at(x, y, c) = bgr[2 - c] / 255.0f;
    }
  return result;
}

}  // namespace

double write_frame_preview(const render::Scene& scene, const std::string& out_dir) {
  const std::filesystem::path out(out_dir);
  std::filesystem::create_directories(out);
  const render::Renderer renderer(scene);
  const Stopwatch watch;
  const render::FrameBuffers frame = renderer.render(scene.trajectory.front(), 0);
  const double render_ms = watch.elapsed_ms();
  io::write_image((out / "rgb.png").string(),
                  render::expose_colour(frame.radiance, scene.camera, scene.seed, 0));
  io::write_image((out / "depth.png").string(), false_colour_depth(frame.depth));
  io::write_image((out / "kd.png").string(), srgb_for_display(frame.kd));
  io::write_image((out / "ks.png").string(), srgb_for_display(frame.ks));
  io::write_image((out / "alpha.png").string(), scaled_grey(frame.alpha, kAlphaWhite));
  return render_ms;
}

}  // namespace glint::app
