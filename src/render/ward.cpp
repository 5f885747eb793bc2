#include "render/ward.h"

#include <bit>
#include <cstdint>

namespace glint::render {
namespace {

// exp(x) for x in [-40, 0] without a library call, so that the loop below vectorises: x =
// n ln 2 + r with |r| <= ln 2 / 2 (ln 2 split in two for an exact product), exp(r) by its
// degree-7 Taylor polynomial (relative error below 2e-7 there), 2^n by building the exponent.
inline float exp_nonpositive(float x) {
  constexpr float kLog2e = 1.44269504f, kLn2High = 0.693145752f, kLn2Low = 1.42860677e-6f;
  constexpr float kRound = 12582912.0f;  // 1.5 * 2^23: adding it rounds to an integer
  const float n = (x * kLog2e + kRound) - kRound;
  const float r = (x - n * kLn2High) - n * kLn2Low;
  float p = 1.0f / 5040;
  p = p * r + 1.0f / 720;
  p = p * r + 1.0f / 120;
  p = p * r + 1.0f / 24;
  p = p * r + 1.0f / 6;
  p = p * r + 0.5f;
  p = p * r + 1.0f;
  p = p * r + 1.0f;
  const float scale = std::bit_cast<float>((static_cast<std::int32_t>(n) + 127) << 23);
  return p * scale;
}

}  // namespace

#if defined(__x86_64__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void ward_specular_lobes(const Eigen::Vector3f& n, const Eigen::Vector3f& wi, DirectionArrays wo,
                         int count, float alpha, float* lobe) {
  const float cos_i = n.dot(wi);
  if (cos_i <= kGrazingCosine) {
    std::fill_n(lobe, count, 0.0f);
    return;
  }
  const float a = std::max(alpha, kMinWardAlpha);
  const float inverse_a2 = 1.0f / (a * a);
  const float factor = 1.0f / (4.0f * float(M_PI) * a * a * std::sqrt(cos_i));  // eq. (3)
  const float nx = n.x(), ny = n.y(), nz = n.z(), ix = wi.x(), iy = wi.y(), iz = wi.z();
  const float* __restrict ox = wo.x;
  const float* __restrict oy = wo.y;
  const float* __restrict oz = wo.z;
  float* __restrict out = lobe;
  // The same rule as ward_specular_lobe(), written without branches.
  for (int j = 0; j < count; ++j) {
    const float cos_o = nx * ox[j] + ny * oy[j] + nz * oz[j];
    const float hx = ix + ox[j], hy = iy + oy[j], hz = iz + oz[j];
    const float n_h = nx * hx + ny * hy + nz * hz;
    const float h2 = std::max(hx * hx + hy * hy + hz * hz, 1e-20f);
    const float cos_h2 = std::min(1.0f, n_h * n_h / h2);
    const float tan_h2 = (1.0f - cos_h2) / std::max(cos_h2, 1e-20f);
    const float gamma = -tan_h2 * inverse_a2;  // eq. (4)
    const float value = exp_nonpositive(std::max(gamma, -40.0f)) * factor /
                        std::sqrt(std::max(cos_o, kGrazingCosine));
    // Three selects, not one on a combined condition: GCC 12 vectorises only this form.
    const float above = cos_o > kGrazingCosine ? value : 0.0f;
    const float lit = cos_h2 > 0.0f ? above : 0.0f;
    out[j] = gamma >= -40.0f ? lit : 0.0f;
  }
}

#if defined(__x86_64__)
__attribute__((target_clones("arch=x86-64-v3", "default")))
#endif
void ward_roughness_factors(const float* tan2_h, int count, float alpha, float* factor) {
  const float a = std::max(alpha, kMinWardAlpha);
  const float inverse_a2 = 1.0f / (a * a);
  const float* __restrict in = tan2_h;
  float* __restrict out = factor;
  for (int j = 0; j < count; ++j) {
    const float gamma = -in[j] * inverse_a2;  // eq. (4)
    const float value = exp_nonpositive(std::max(gamma, -40.0f)) * inverse_a2;
    out[j] = gamma >= -40.0f ? value : 0.0f;
  }
}

}  // namespace glint::render
