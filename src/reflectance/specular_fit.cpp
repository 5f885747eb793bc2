#include "reflectance/specular_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "reflectance/light_incidence.h"
#include "render/ward.h"

namespace glint::reflectance {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// The fit's data in structure-of-arrays form. A term is one (observation, light) pair whose
// lobe can be non-zero: its tan^2(theta_h) and L_l cos(theta_i) / (4 pi sqrt(cos_i cos_o)) per
// channel, so that the lobe sum of eq. (6) at roughness alpha is
//   G_k = sum over k's terms of weight * exp(-tan2 / alpha^2) / alpha^2      (eqs 3-4)
// A voxel's observations with no clipped channel are data; those with one are bounds: the
// radiance of a clipped channel was at least the clip level, so the model's prediction there
// (the voxel's diffuse term, fitted from its data, plus ks G_k) should reach it. A sharp
// highlight's peak clips, and without its bounds the fit saw only the peak's flanks and took
// them for a weak lobe (the yellow bunny: ks 0.05 against 0.2).
class LobeProblem {
 public:
  LobeProblem(const std::vector<FitVoxel>& voxels, const std::vector<render::PointLight>& lights,
              const SpecularFitParams& params);

  int observations() const { return data_; }
  double variation() const { return variation_.sum(); }

  // The squared residual of the best ks at `alpha` (summed over channels; a bound the lobe
  // falls short of counts its shortfall squared); the slope into *ks.
  double residual(float alpha, Eigen::Vector3f* ks) const;

 private:
  void add_voxel(const FitVoxel& voxel, const std::vector<render::PointLight>& lights,
                 const SpecularFitParams& params);

  std::vector<float> tan2_;
  std::vector<Eigen::Vector3f> weight_;
  std::vector<int> term_observation_;
  // Per observation: a datum's colour minus its voxel's mean datum; a bound's clip level minus
  // that mean in its clipped channels, NaN in the others.
  std::vector<Eigen::Vector3f> centred_colour_;
  // Per voxel: its data are observations [previous end, data end), its bounds [data end, end).
  std::vector<int> voxel_data_end_, voxel_end_;
  std::vector<int> bounds_;  // the bounds' observations, of every voxel
  int data_ = 0;
  Eigen::Vector3d variation_ = Eigen::Vector3d::Zero();  // sum of the data's centred_colour^2
  std::vector<Incidence> lit_;                           // scratch of add_voxel()
  std::vector<int> clipped_;                             // scratch of add_voxel()
  mutable std::vector<float> factor_;                    // per term, at the alpha being evaluated
  mutable std::vector<Eigen::Vector3f> lobe_sum_;
};

LobeProblem::LobeProblem(const std::vector<FitVoxel>& voxels,
                         const std::vector<render::PointLight>& lights,
                         const SpecularFitParams& params) {
  for (const FitVoxel& voxel : voxels) add_voxel(voxel, lights, params);
  lobe_sum_.resize(centred_colour_.size());
  factor_.resize(tan2_.size());
}

void LobeProblem::add_voxel(const FitVoxel& voxel, const std::vector<render::PointLight>& lights,
                            const SpecularFitParams& params) {
  // Beyond it the lobe is below exp(-40) of its peak at every alpha searched.
  const float negligible_tan2 = 40.0f * params.alpha_max * params.alpha_max;
  lit_.clear();  // the lights above the voxel's surface, once per voxel
  for (std::size_t l = 0; l < lights.size(); ++l)
    if (const Incidence in = incidence(lights, l, voxel.position, voxel.normal, voxel.lighting);
        in.cosine > render::kGrazingCosine)
      lit_.push_back(in);
  const std::size_t first = centred_colour_.size(), first_term = tan2_.size();
  const auto add_terms = [&](const Eigen::Vector3f& direction, float cos_o) {
    const int index = int(centred_colour_.size());
    if (cos_o > render::kGrazingCosine)  // a grazing view has no lobe term (render/ward.h)
      for (const Incidence& in : lit_) {
        const float tan2 = render::ward_half_angle_tan2(voxel.normal, in.direction, direction);
        if (tan2 > negligible_tan2) continue;  // no lobe in the searched range reaches it
        tan2_.push_back(tan2);
        weight_.push_back(in.irradiance / (4.0f * float(M_PI) * std::sqrt(in.cosine * cos_o)));
        term_observation_.push_back(index);
      }
  };
  // The data first, then the bounds.
  clipped_.clear();
  Eigen::Vector3f mean = Eigen::Vector3f::Zero();
  const int count = std::min(voxel.count, kMaxObservationsPerVoxel);
  for (int k = 0; k < count; ++k) {
    const Observation& o = voxel.observations[k];
    const float cos_o = voxel.normal.dot(o.direction());
    if (!(cos_o > 0.0f)) continue;
    const Eigen::Vector3f colour = o.colour();
    if (!(colour.maxCoeff() < params.saturated_radiance)) {
      if (params.clipped_as_bounds) clipped_.push_back(k);
      continue;
    }
    add_terms(o.direction(), cos_o);
    centred_colour_.push_back(colour);
    mean += colour;
  }
  const int data = int(centred_colour_.size() - first);
  if (data < 2) {  // one observation has no variation to explain, nor a diffuse term to fit
    centred_colour_.resize(first);
    tan2_.resize(first_term);
    weight_.resize(first_term);
    term_observation_.resize(first_term);
    return;
  }
  mean /= float(data);
  for (std::size_t k = first; k < centred_colour_.size(); ++k) {
    centred_colour_[k] -= mean;
    variation_ += centred_colour_[k].cast<double>().cwiseAbs2();
  }
  data_ += data;
  voxel_data_end_.push_back(int(centred_colour_.size()));
  for (const int k : clipped_) {
    const Observation& o = voxel.observations[k];
    const Eigen::Vector3f direction = o.direction(), colour = o.colour();
    add_terms(direction, voxel.normal.dot(direction));
    Eigen::Vector3f bound;
    for (int c = 0; c < 3; ++c)
      bound[c] =
          colour[c] >= params.saturated_radiance ? params.saturated_radiance - mean[c] : kNaN;
    bounds_.push_back(int(centred_colour_.size()));
    centred_colour_.push_back(bound);
  }
  voxel_end_.push_back(int(centred_colour_.size()));
}

double LobeProblem::residual(float alpha, Eigen::Vector3f* ks) const {
  render::ward_roughness_factors(tan2_.data(), int(tan2_.size()), alpha, factor_.data());
  std::fill(lobe_sum_.begin(), lobe_sum_.end(), Eigen::Vector3f::Zero());
  for (std::size_t t = 0; t < tan2_.size(); ++t)
    lobe_sum_[term_observation_[t]] += weight_[t] * factor_[t];
  // Per channel: the slope of the data's centred colours over their centred lobe sums; every
  // lobe sum is centred on its voxel's data mean (lobe_sum_ holds them centred from here on).
  Eigen::Vector3d covariance = Eigen::Vector3d::Zero(), lobe_variation = Eigen::Vector3d::Zero();
  int begin = 0;
  for (std::size_t v = 0; v < voxel_end_.size(); ++v) {
    const int data_end = voxel_data_end_[v], end = voxel_end_[v];
    Eigen::Vector3f mean = Eigen::Vector3f::Zero();
    for (int k = begin; k < data_end; ++k) mean += lobe_sum_[k];
    mean /= float(data_end - begin);
    for (int k = begin; k < end; ++k) lobe_sum_[k] -= mean;
    for (int k = begin; k < data_end; ++k) {
      const Eigen::Vector3d g = lobe_sum_[k].cast<double>();
      covariance += g.cwiseProduct(centred_colour_[k].cast<double>());
      lobe_variation += g.cwiseAbs2();
    }
    begin = end;
  }
  double squared = 0;
  for (int c = 0; c < 3; ++c) {
    // ks >= 0: a lobe that anti-correlates with the observations fits as no lobe.
    const auto slope_of = [](double covariance, double variation) {
      return covariance > 0 && variation > 0 ? covariance / variation : 0.0;
    };
    double slope = slope_of(covariance[c], lobe_variation[c]);
    // The bounds the lobe falls short of join the data (each a squared shortfall, linear in ks
    // like a datum), refitting until that set stays the same (at most four rounds). The sums
    // are those of the set at the final slope, so the residual is the censored objective there.
    double bound_covariance = 0, bound_variation = 0, bound_squares = 0;
    for (int round = 0;; ++round) {
      double cov = 0, var = 0, squares = 0;
      for (const int k : bounds_) {
        const double bound = centred_colour_[k][c], g = lobe_sum_[k][c];
        if (!(bound > slope * g)) continue;  // reached (or not clipped in this channel)
        cov += bound * g;
        var += g * g;
        squares += bound * bound;
      }
      const bool same = round > 0 && cov == bound_covariance && var == bound_variation;
      bound_covariance = cov, bound_variation = var, bound_squares = squares;
      if (same || round == 3) break;
      slope = slope_of(covariance[c] + cov, lobe_variation[c] + var);
    }
    (*ks)[c] = float(slope);
    // sum (x - slope g)^2 over the data and the active bounds.
    squared += variation_[c] + bound_squares - 2 * slope * (covariance[c] + bound_covariance) +
               slope * slope * (lobe_variation[c] + bound_variation);
  }
  return squared;
}

}  // namespace

std::optional<SpecularFit> fit_specular(const std::vector<FitVoxel>& voxels,
                                        const std::vector<render::PointLight>& lights,
                                        const SpecularFitParams& params) {
  const LobeProblem problem(voxels, lights, params);
  if (!(problem.variation() > 0)) return std::nullopt;
  const double lo = std::log(params.alpha_min), hi = std::log(params.alpha_max);
  const int steps = std::max(params.scan_steps, 2);
  auto log_alpha = [&](int i) { return lo + (hi - lo) * i / (steps - 1); };
  Eigen::Vector3f ks;
  auto residual = [&](double u) { return problem.residual(float(std::exp(u)), &ks); };

  int best = 0;
  double best_residual = residual(log_alpha(0));
  for (int i = 1; i < steps; ++i) {
    const double r = residual(log_alpha(i));
    if (r < best_residual) best_residual = r, best = i;
  }
  // Golden-section search between the scan's neighbours of its best alpha.
  const double ratio = 0.5 * (std::sqrt(5.0) - 1.0);
  double a = log_alpha(std::max(best - 1, 0)), b = log_alpha(std::min(best + 1, steps - 1));
  double x1 = b - ratio * (b - a), x2 = a + ratio * (b - a);
  double r1 = residual(x1), r2 = residual(x2);
  for (int i = 0; i < params.refine_steps; ++i) {
    if (r1 < r2) {
      b = x2, x2 = x1, r2 = r1;
      x1 = b - ratio * (b - a), r1 = residual(x1);
    } else {
      a = x1, x1 = x2, r1 = r2;
      x2 = a + ratio * (b - a), r2 = residual(x2);
    }
  }
  double u = r1 < r2 ? x1 : x2, r = std::min(r1, r2);
  if (best_residual < r) u = log_alpha(best), r = best_residual;

  SpecularFit fit;
  fit.alpha = float(std::exp(u));
  problem.residual(fit.alpha, &fit.ks);
  fit.explained = float(std::clamp(1.0 - r / problem.variation(), 0.0, 1.0));
  fit.observations = problem.observations();
  // ks > 1 reflects more than arrives: the lobe is fitting something else (typically a few
  // unsaturated samples on the flank of a clipped, misaligned highlight).
  if (fit.explained < params.min_explained || fit.ks.maxCoeff() > 1.0f) return std::nullopt;
  return fit;
}

}  // namespace glint::reflectance
