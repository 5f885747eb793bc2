#include "render/ward.h"

#include "core/fast_exp.h"

namespace glint::render {

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
