#include "geometry/covariance.h"

#include <Eigen/Geometry>
#include <algorithm>
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

// Eigenvalues in descending order, unclamped (Smith 1961: A = qI + pB, eig(B) = 2cos(φ + 2πj/3)).
Eigen::Vector3d raw_eigenvalues(const SymmetricMatrix3& m) {
  const double off = m.xy * m.xy + m.xz * m.xz + m.yz * m.yz;
  const double q = (m.xx + m.yy + m.zz) / 3.0;
  const double dxx = m.xx - q, dyy = m.yy - q, dzz = m.zz - q;
  const double p2 = dxx * dxx + dyy * dyy + dzz * dzz + 2.0 * off;
  if (p2 <= 0.0) return {q, q, q};
  const double p = std::sqrt(p2 / 6.0);
  // det(B) / 2 with B = (A - qI) / p.
  const double det = dxx * (dyy * dzz - m.yz * m.yz) - m.xy * (m.xy * dzz - m.yz * m.xz) +
                     m.xz * (m.xy * m.yz - dyy * m.xz);
  const double r = std::clamp(det / (2.0 * p * p * p), -1.0, 1.0);
  const double phi = std::acos(r) / 3.0;
  // cos(φ + 2π/3) = -cos(φ)/2 - sin(φ)·√3/2: one sin/cos pair instead of two cosines.
  const double cos_phi = std::cos(phi), sin_phi = std::sin(phi);
  const double largest = q + 2.0 * p * cos_phi;
  const double smallest = q + p * (-cos_phi - std::numbers::sqrt3 * sin_phi);
  return {largest, 3.0 * q - largest - smallest, smallest};
}

}  // namespace

Eigen::Vector3d eigenvalues_descending(const SymmetricMatrix3& m) {
  return raw_eigenvalues(m).cwiseMax(0.0);
}

Eigen::Vector3d smallest_eigenvector(const SymmetricMatrix3& m) {
  const double lambda = raw_eigenvalues(m)[2];
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
