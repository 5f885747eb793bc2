#include "point_preview.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <opencv2/imgcodecs.hpp>

#include "core/error.h"
#include "io/atomic_file.h"

namespace glint::app {

std::vector<std::uint8_t> encode_point_preview(const std::string& path, const PointCloud& cloud,
                                               const PreviewParams& params) {
  const std::size_t n = cloud.size();
  if (n == 0) throw Error(path, "", "nothing to draw: the cloud is empty");
  const auto* red = cloud.get<std::uint8_t>("red");
  const auto* green = cloud.get<std::uint8_t>("green");
  const auto* blue = cloud.get<std::uint8_t>("blue");
  if (!red || !green || !blue) throw Error(path, "", "the cloud has no uchar red/green/blue");

  const double azimuth = params.azimuth_deg * std::numbers::pi / 180.0;
  const double elevation = params.elevation_deg * std::numbers::pi / 180.0;
  // Screen axes (right, up) and the viewing direction, in a z-up frame.
  const double right[3] = {std::cos(azimuth), std::sin(azimuth), 0.0};
  const double up[3] = {-std::sin(elevation) * std::sin(azimuth),
                        std::sin(elevation) * std::cos(azimuth), std::cos(elevation)};
  const double toward_viewer[3] = {std::cos(elevation) * std::sin(azimuth),
                                   -std::cos(elevation) * std::cos(azimuth), std::sin(elevation)};
  auto coordinates = [&](std::size_t i) {
    // Map y-up clouds into the z-up frame.
    return params.up_axis == 'y'
               ? std::array<double, 3>{cloud.x[i], -double(cloud.z[i]), cloud.y[i]}
               : std::array<double, 3>{cloud.x[i], cloud.y[i], cloud.z[i]};
  };
  std::vector<double> u(n), v(n), depth(n);
  double u_min = std::numeric_limits<double>::max(), u_max = -u_min, v_min = u_min, v_max = -u_min;
  double d_min = u_min, d_max = -u_min;
  for (std::size_t i = 0; i < n; ++i) {
    const auto p = coordinates(i);
    u[i] = p[0] * right[0] + p[1] * right[1] + p[2] * right[2];
    v[i] = p[0] * up[0] + p[1] * up[1] + p[2] * up[2];
    depth[i] = p[0] * toward_viewer[0] + p[1] * toward_viewer[1] + p[2] * toward_viewer[2];
    u_min = std::min(u_min, u[i]), u_max = std::max(u_max, u[i]);
    v_min = std::min(v_min, v[i]), v_max = std::max(v_max, v[i]);
    d_min = std::min(d_min, depth[i]), d_max = std::max(d_max, depth[i]);
  }
  const int margin = 20;
  const double extent = std::max({u_max - u_min, v_max - v_min, 1e-12});
  const double pixels_per_unit =
      std::min(params.width - 2 * margin, params.height - 2 * margin) / extent;
  // Splats large enough to close the gaps of an evenly sampled surface.
  const double covered = (u_max - u_min) * (v_max - v_min) * pixels_per_unit * pixels_per_unit;
  const int radius = std::clamp(int(std::lround(0.6 * std::sqrt(covered / double(n)))), 1, 6);

  cv::Mat image(params.height, params.width, CV_8UC3, cv::Scalar(255, 255, 255));
  std::vector<double> zbuffer(std::size_t(params.width) * params.height,
                              -std::numeric_limits<double>::max());
  const double centre_u = 0.5 * (u_min + u_max), centre_v = 0.5 * (v_min + v_max);
  for (std::size_t i = 0; i < n; ++i) {
    const int px = int(std::lround(params.width / 2.0 + (u[i] - centre_u) * pixels_per_unit));
    const int py = int(std::lround(params.height / 2.0 - (v[i] - centre_v) * pixels_per_unit));
    const double shade = 0.55 + 0.45 * (d_max > d_min ? (depth[i] - d_min) / (d_max - d_min) : 1.0);
    const cv::Vec3b colour(cv::saturate_cast<uchar>((*blue)[i] * shade),
                           cv::saturate_cast<uchar>((*green)[i] * shade),
                           cv::saturate_cast<uchar>((*red)[i] * shade));
    for (int y = std::max(0, py - radius); y <= std::min(params.height - 1, py + radius); ++y) {
      for (int x = std::max(0, px - radius); x <= std::min(params.width - 1, px + radius); ++x) {
        double& z = zbuffer[std::size_t(y) * params.width + x];
        if (depth[i] > z) {
          z = depth[i];
          image.at<cv::Vec3b>(y, x) = colour;
        }
      }
    }
  }
  std::vector<std::uint8_t> png;
  if (!cv::imencode(".png", image, png)) throw Error(path, "", "could not encode the PNG");
  return png;
}

void write_png_bytes(const std::string& path, const std::vector<std::uint8_t>& png) {
  io::AtomicFile file(path);
  file.stream().write(reinterpret_cast<const char*>(png.data()),
                      static_cast<std::streamsize>(png.size()));
  file.commit();
}

void write_point_preview(const std::string& path, const PointCloud& cloud,
                         const PreviewParams& params) {
  write_png_bytes(path, encode_point_preview(path, cloud, params));
}

}  // namespace glint::app
