#pragma once
// The decaying per-pixel loss weight of guided DIP, eq. (16) of the guided-denoising paper.
#include <cmath>

namespace glint::denoise {

struct DecayParams {
  int warmup = 225;     // κw: iterations with full weight
  double rate = 0.15;   // κr
  double floor = 0.02;  // κc: the weight converges to this, never to 0
};

// w_dec at iteration i for a pixel of importance m ∈ [0,1]: 1 during warm-up, then
// (0.9 + 0.1 m)^((i − κw)·κr)·(1 − κc) + κc. m = 1 keeps weight 1 for ever (detail is fitted);
// m = 0 decays fastest (the pixel stops being fitted, i.e. early stopping per pixel).
inline double decay_weight(int iteration, double importance, const DecayParams& p) {
  if (iteration < p.warmup) return 1.0;
  const double base = 0.9 + 0.1 * importance;
  return std::pow(base, (iteration - p.warmup) * p.rate) * (1.0 - p.floor) + p.floor;
}

}  // namespace glint::denoise
