#pragma once
// The indirect light the pipeline cannot trace (glint's addition to paper 1): light bounced off
// surfaces the camera never saw, which the gather (reflectance/light_transport.h) counts as
// unknown or dark, or all indirect light where the gather is off. A segment of one albedo kd
// shows at each voxel the diffuse radiance
//   D = kd / pi * (E + A)
// with E the irradiance the pipeline knows (the lights that reach the voxel, its gathered
// indirect light) and A the segment's unseen irradiance, taken as the same over the segment.
// Over the segment's voxels D is then a line in E, slope kd / pi and intercept kd A / pi, so
// A = intercept / slope. Shadows give the line its leverage: a voxel that no light reaches shows
// kd / pi * A alone. The line is Tukey's three-group resistant line (Hoaglin, Mosteller & Tukey,
// "Understanding Robust and Exploratory Data Analysis", 1983, ch. 5): the medians of the thirds
// with the lowest and the highest E give the slope, the median residual the intercept, so that
// neither a voxel whose shadow the fused geometry misses nor a mispredicted highlight moves it.
#include <Eigen/Core>
#include <optional>
#include <span>
#include <vector>

namespace glint::reflectance {

struct UnseenLightFitParams {
  int min_voxels = 48;  // 16 per third: the median of each stays within a few voxels' noise
  // The highest third's median irradiance (luminance) must be at least this multiple of the
  // lowest third's: below it the intercept is an extrapolation over more than the data's span.
  float min_leverage = 2.0f;
  // An unseen irradiance (its mean over the channels) below this share of the segment's typical
  // known irradiance counts as none: where a rendering has no indirect light at all, the fits'
  // intercepts still come to a few hundredths of it (the errors of the specular term, the
  // normals and the lights' falloff), which would darken every albedo by as much.
  float min_share = 0.1f;
};

// The line D = slope * E + intercept, per channel, and the typical known irradiance E of the
// voxels it was fitted to (the highest third's median luminance).
struct RadianceLine {
  Eigen::Vector3f slope = Eigen::Vector3f::Zero(), intercept = Eigen::Vector3f::Zero();
  float typical_irradiance = 0.0f;
};

// The line through the voxels' known irradiance E and diffuse radiance D (same length); nullopt
// with fewer than min_voxels, too little spread in E, or a slope that is not positive in some
// channel. The intercept is not clamped: fits of a segment without unseen light scatter about
// zero, and their average stays there. `order` is scratch.
std::optional<RadianceLine> fit_radiance_line(std::span<const Eigen::Vector3f> irradiance,
                                              std::span<const Eigen::Vector3f> radiance,
                                              const UnseenLightFitParams& params,
                                              std::vector<int>& order);

// A = intercept / slope per channel, at least 0; zero where its mean is under min_share of the
// line's typical irradiance.
inline Eigen::Vector3f unseen_irradiance(const RadianceLine& line, float min_share) {
  const Eigen::Vector3f unseen = line.intercept.cwiseQuotient(line.slope).cwiseMax(0.0f);
  if (!(unseen.mean() >= min_share * line.typical_irradiance)) return Eigen::Vector3f::Zero();
  return unseen;
}

}  // namespace glint::reflectance
