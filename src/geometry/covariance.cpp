#include "geometry/covariance.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

namespace glint::geometry {

SymmetricMatrix3 Moments::covariance() const {
  const double n = s_[0];
  const Eigen::Vector3d m = mean();
  return {s_[4] / n - m.x() * m.x(), s_[5] / n - m.x() * m.y(), s_[6] / n - m.x() * m.z(),
          s_[7] / n - m.y() * m.y(), s_[8] / n - m.y() * m.z(), s_[9] / n - m.z() * m.z()};
}

namespace {

// Taylor coefficients, computed at compile time: asin x = x·Σ a_n x^2n (a_n = (2n)!/(4^n (n!)²
// (2n+1))), and the even and odd series of cos and sin.
template <int Terms>
constexpr std::array<double, Terms> asin_series() {
  std::array<double, Terms> a{};
  double central = 1.0;  // (2n)!/(4^n (n!)²)
  for (int n = 0; n < Terms; ++n) {
    a[n] = central / (2 * n + 1);
    central *= double(2 * n + 1) / double(2 * n + 2);
  }
  return a;
}
template <int Terms>
constexpr std::array<double, Terms> trig_series(int first_power) {
  std::array<double, Terms> a{};
  double term = 1.0;
  for (int power = 1; power <= first_power; ++power) term /= power;
  for (int n = 0; n < Terms; ++n) {
    a[n] = term;
    term *= -1.0 / ((first_power + 2 * n + 1) * (first_power + 2 * n + 2));
  }
  return a;
}
// |x| <= 1/2: the first omitted asin term is below 3e-17; phi <= pi/3: the cos and sin
// series stop below 1e-17.
constexpr auto kAsin = asin_series<24>();
constexpr auto kCos = trig_series<11>(0);
constexpr auto kSin = trig_series<10>(1);

template <std::size_t Terms>
inline double horner(const std::array<double, Terms>& a, double z) {
  double sum = a[Terms - 1];
#pragma GCC unroll 32
  for (int n = int(Terms) - 2; n >= 0; --n) sum = sum * z + a[n];
  return sum;
}

// acos through asin of an argument of at most 1/2 (the half-angle form beyond |r| = 1/2), so
// one polynomial serves all r, branch-free: the loops below vectorise across matrices.
inline double acos_polynomial(double r) {
  const double magnitude = std::abs(r);
  const bool central = magnitude <= 0.5;
  const double half_angle = std::sqrt((1.0 - magnitude) * 0.5);
  const double x = central ? r : half_angle;
  const double asin_x = x * horner(kAsin, x * x);
  const double outer = r > 0 ? 2.0 * asin_x : std::numbers::pi - 2.0 * asin_x;
  return central ? std::numbers::pi / 2 - asin_x : outer;
}

// Eigenvalues of `Lanes` matrices given entry by entry, descending and clamped at zero
// (Smith 1961: A = qI + pB, eig(B) = 2cos(φ + 2πj/3)). One code path for one matrix and for
// a batch, so both give the same values up to rounding.
template <int Lanes>
inline void eigenvalues_lanes(const double* xx, const double* xy, const double* xz,
                              const double* yy, const double* yz, const double* zz, double* largest,
                              double* middle, double* smallest) {
  for (int i = 0; i < Lanes; ++i) {
    const double off = xy[i] * xy[i] + xz[i] * xz[i] + yz[i] * yz[i];
    const double q = (xx[i] + yy[i] + zz[i]) / 3.0;
    const double dxx = xx[i] - q, dyy = yy[i] - q, dzz = zz[i] - q;
    const double p2 = dxx * dxx + dyy * dyy + dzz * dzz + 2.0 * off;
    const bool isotropic = !(p2 > 0.0);
    const double p = std::sqrt(isotropic ? 1.0 : p2 / 6.0);
    // det(B) / 2 with B = (A - qI) / p.
    const double det = dxx * (dyy * dzz - yz[i] * yz[i]) - xy[i] * (xy[i] * dzz - yz[i] * xz[i]) +
                       xz[i] * (xy[i] * yz[i] - dyy * xz[i]);
    const double r = std::min(1.0, std::max(-1.0, det / (2.0 * p * p * p)));
    // One matrix: libm (a flat patch's zero eigenvalue stays exactly zero, as the denoisers'
    // noise maps expect); a batch: the polynomials, which vectorise.
    double cos_phi, sin_phi;
    if constexpr (Lanes == 1) {
      const double phi = std::acos(r) / 3.0;
      cos_phi = std::cos(phi), sin_phi = std::sin(phi);
    } else {
      const double phi = acos_polynomial(r) / 3.0, phi2 = phi * phi;
      cos_phi = horner(kCos, phi2), sin_phi = phi * horner(kSin, phi2);
    }
    // cos(φ + 2π/3) = -cos(φ)/2 - sin(φ)·√3/2.
    const double first = isotropic ? q : q + 2.0 * p * cos_phi;
    const double last = isotropic ? q : q + p * (-cos_phi - std::numbers::sqrt3 * sin_phi);
    largest[i] = std::max(0.0, first);
    middle[i] = std::max(0.0, 3.0 * q - first - last);
    smallest[i] = std::max(0.0, last);
  }
}

}  // namespace

Eigen::Vector3d eigenvalues_descending(const SymmetricMatrix3& m) {
  Eigen::Vector3d out;
  eigenvalues_lanes<1>(&m.xx, &m.xy, &m.xz, &m.yy, &m.yz, &m.zz, &out[0], &out[1], &out[2]);
  return out;
}

#if defined(__x86_64__)
__attribute__((target_clones("arch=x86-64-v3", "default"), flatten))
#endif
void eigenvalues_descending(const SymmetricMatrix3* m, int count, Eigen::Vector3d* out) {
  constexpr int lanes = 8;
  for (int first = 0; first < count; first += lanes) {
    // Entry by entry (structure of arrays); unused lanes hold zero matrices.
    double xx[lanes] = {}, xy[lanes] = {}, xz[lanes] = {}, yy[lanes] = {}, yz[lanes] = {},
           zz[lanes] = {}, largest[lanes], middle[lanes], smallest[lanes];
    const int used = std::min(lanes, count - first);
    for (int i = 0; i < used; ++i) {
      const SymmetricMatrix3& a = m[first + i];
      xx[i] = a.xx, xy[i] = a.xy, xz[i] = a.xz, yy[i] = a.yy, yz[i] = a.yz, zz[i] = a.zz;
    }
    eigenvalues_lanes<lanes>(xx, xy, xz, yy, yz, zz, largest, middle, smallest);
    for (int i = 0; i < used; ++i) out[first + i] = {largest[i], middle[i], smallest[i]};
  }
}

Eigen::Vector3d smallest_eigenvector(const SymmetricMatrix3& m) {
  return smallest_eigenvector(m, eigenvalues_descending(m)[2]);
}

Eigen::Vector3d smallest_eigenvector(const SymmetricMatrix3& m, double lambda) {
  // Rows of A - λI span the plane orthogonal to the eigenvector: the largest cross product of
  // two rows is the most accurate direction.
  const Eigen::Vector3d r0(m.xx - lambda, m.xy, m.xz);
  const Eigen::Vector3d r1(m.xy, m.yy - lambda, m.yz);
  const Eigen::Vector3d r2(m.xz, m.yz, m.zz - lambda);
  const Eigen::Vector3d c01 = r0.cross(r1), c02 = r0.cross(r2), c12 = r1.cross(r2);
  const double n01 = c01.squaredNorm(), n02 = c02.squaredNorm(), n12 = c12.squaredNorm();
  if (n01 >= n02 && n01 >= n12 && n01 > 0) return c01 / std::sqrt(n01);
  if (n02 >= n12 && n02 > 0) return c02 / std::sqrt(n02);
  if (n12 > 0) return c12 / std::sqrt(n12);
  // Two or three equal smallest eigenvalues: any vector orthogonal to the remaining row works.
  const Eigen::Vector3d rows[3] = {r0, r1, r2};
  const Eigen::Vector3d* strongest = &rows[0];
  for (const auto& row : rows) {
    if (row.squaredNorm() > strongest->squaredNorm()) strongest = &row;
  }
  if (strongest->squaredNorm() == 0) return Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d helper = std::abs(strongest->x()) < 0.9 * strongest->norm()
                                     ? Eigen::Vector3d::UnitX()
                                     : Eigen::Vector3d::UnitY();
  return strongest->cross(helper).normalized();
}

}  // namespace glint::geometry
