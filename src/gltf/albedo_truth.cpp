#include "gltf/albedo_truth.h"

#include <cmath>
#include <limits>

#include "core/error.h"
#include "io/rgbd_sequence.h"
#include "reflectance/material_evaluation.h"

namespace glint::gltf {
namespace {

// A frame sees a point when its true depth there is this close to the point's: the mesh lies
// within a few millimetres of the true surface (TSDF at 5 mm, simplification's deviation).
constexpr float kDepthToleranceM = 0.02f;

struct ErrorSum {
  double absolute = 0, squared = 0;
  std::size_t texels = 0;
  nlohmann::json to_json() const {
    if (texels == 0) return {{"texels", 0}};
    const double mse = squared / double(3 * texels);
    return {{"texels", texels},
            {"l1", absolute / double(3 * texels)},
            {"psnr", mse > 0 ? 10 * std::log10(1 / mse) : 99.0}};
  }
};

}  // namespace

AlbedoTruth::AlbedoTruth(const std::string& folder, int stride) {
  const io::RgbdSequence sequence = io::open_rgbd_sequence(folder);
  if (!reflectance::has_ground_truth_maps(sequence))
    throw Error(folder, "gt", "no ground-truth maps (a sequence from glint render / glint synth)");
  sequence.require_ground_truth(sequence.frames.size(), "--albedo-truth needs every pose");
  intrinsics_ = sequence.intrinsics;
  for (std::size_t i = 0; i < sequence.frames.size(); i += std::size_t(std::max(stride, 1))) {
    View view;
    view.world_to_camera = sequence.frames[i].ground_truth->inverse();
    view.kd = reflectance::read_ground_truth_map(sequence, i, "kd", 3);
    view.depth_m = reflectance::read_ground_truth_map(sequence, i, "depth", 1);
    views_.push_back(std::move(view));
  }
}

Eigen::Vector3f AlbedoTruth::operator()(const Eigen::Vector3f& p) const {
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  int seen = 0;
  for (const View& view : views_) {
    const Eigen::Vector3d q = view.world_to_camera * p.cast<double>();
    if (q.z() <= 0) continue;
    const Eigen::Vector2d pixel = intrinsics_.project(q);
    const int x = int(std::lround(pixel.x())), y = int(std::lround(pixel.y()));
    if (x < 0 || y < 0 || x >= view.depth_m.width() || y >= view.depth_m.height()) continue;
    if (std::abs(view.depth_m.at(x, y, 0) - float(q.z())) > kDepthToleranceM) continue;
    for (int c = 0; c < 3; ++c) sum[c] += view.kd.at(x, y, c);
    ++seen;
  }
  if (seen == 0) return Eigen::Vector3f::Constant(std::numeric_limits<float>::quiet_NaN());
  return sum / float(seen);
}

nlohmann::json albedo_errors(const ImageF& atlas, const ImageF& truth, const ImageF& observations,
                             const std::vector<std::uint8_t>& baked, float well_observed) {
  ErrorSum all, well, poor;
  for (std::size_t i = 0; i < baked.size(); ++i) {
    if (!baked[i] || !std::isfinite(truth.plane(0)[i])) continue;
    double absolute = 0, squared = 0;
    for (int c = 0; c < 3; ++c) {
      const double d = double(atlas.plane(c)[i]) - truth.plane(c)[i];
      absolute += std::abs(d);
      squared += d * d;
    }
    for (ErrorSum* sum : {&all, observations.plane(0)[i] >= well_observed ? &well : &poor}) {
      sum->absolute += absolute;
      sum->squared += squared;
      ++sum->texels;
    }
  }
  return {{"all", all.to_json()},
          {"well_observed", well.to_json()},
          {"poorly_observed", poor.to_json()},
          {"well_observed_min_observations", well_observed}};
}

}  // namespace glint::gltf
