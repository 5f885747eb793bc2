#pragma once
// Guided Self2Self's per-pixel Bernoulli masks, eqs. (17)-(24) of the guided-denoising paper.
// Each pixel falls into one of four disjoint cases: seen by the network and scored by the loss,
// seen only, scored only, or neither. Plain Self2Self is p_imp = 0, p_d = 1.
#include <cmath>

namespace glint::denoise {

struct MaskParams {
  double keep = 0.7;      // p_m: probability an unimportant pixel is in the network input
  double discard = 0.01;  // p_d: scales both masks down for unimportant pixels
  double exponent = 2.0;  // κm
};

// p_imp = m^κm, eq. (19).
inline double importance_probability(double guidance, double exponent) {
  return std::pow(guidance, exponent);
}

struct MaskProbabilities {
  double both;         // eq. (20): input and target
  double input_only;   // eq. (21)
  double target_only;  // eq. (22)
  double neither;      // eq. (23)
};

inline MaskProbabilities mask_probabilities(double p_imp, const MaskParams& p) {
  MaskProbabilities q;
  q.both = p_imp;
  q.input_only = p.keep * p.discard * (1.0 - p_imp);
  q.target_only = (1.0 - p.keep) * p.discard * (1.0 - p_imp);
  q.neither = 1.0 - (q.both + q.input_only + q.target_only);
  return q;
}

// Importance-modulated dropout rate, eq. (24): important pixels are never dropped.
inline double modulated_dropout(double p_imp, double dropout) { return (1.0 - p_imp) * dropout; }

}  // namespace glint::denoise
