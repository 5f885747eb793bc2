#pragma once
// The decaying per-pixel loss weight of guided DIP, eq. (16) of the guided-denoising paper.
#include <cmath>

namespace glint::denoise {

struct DecayParams {
  int warmup = 225;     // κw: iterations with full weight
  double rate = 0.15;   // κr
  double floor = 0.02;  // κc: the weight converges to this, never to 0
};

// w_dec after the warm-up (i >= κw), eq. (16): (0.9 + 0.1 m)^((i − κw)·κr)·(1 − κc) + κc.
// T is a scalar importance m ∈ [0,1] or a per-pixel importance tensor (pow found by ADL), so
// the training loop and the tests share this one formula.
template <class T>
T decayed_weight(int iteration, const T& importance, const DecayParams& p) {
  using std::pow;
  return pow(0.9 + 0.1 * importance, (iteration - p.warmup) * p.rate) * (1.0 - p.floor) + p.floor;
}

// w_dec at iteration i for a pixel of importance m ∈ [0,1]: 1 during warm-up, then
// decayed_weight. m = 1 keeps weight 1 for ever (detail is fitted); m = 0 decays fastest (the
// pixel stops being fitted, i.e. early stopping per pixel).
inline double decay_weight(int iteration, double importance, const DecayParams& p) {
  return iteration < p.warmup ? 1.0 : decayed_weight(iteration, importance, p);
}

}  // namespace glint::denoise
