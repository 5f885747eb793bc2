#pragma once
// Moments of small point sets and closed-form eigen-analysis of their 3×3 covariance.
// Written for inner loops: no allocation, no iteration; batches call no libm function.
#include <Eigen/Core>
#include <array>

namespace glint::geometry {

// Symmetric 3×3 matrix by its six unique entries.
struct SymmetricMatrix3 {
  double xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
};

// Count, first and second raw moments of a point set; sets can be merged and subtracted, so
// nested or complementary subsets cost no extra pass.
class Moments {
 public:
  Moments() = default;
  // From sums {count, x, y, z, xx, xy, xz, yy, yz, zz} gathered elsewhere (e.g. in float).
  explicit Moments(const std::array<double, 10>& sums) : s_(sums) {}
  void add(double x, double y, double z) { add_weighted(x, y, z, 1.0); }
  // Adds the point with weight w (0 or 1 gives a branch-free subset selection).
  void add_weighted(double x, double y, double z, double w) {
    const double wx = w * x, wy = w * y, wz = w * z;
    s_[0] += w;
    s_[1] += wx, s_[2] += wy, s_[3] += wz;
    s_[4] += wx * x, s_[5] += wx * y, s_[6] += wx * z;
    s_[7] += wy * y, s_[8] += wy * z, s_[9] += wz * z;
  }
  Moments plus(const Moments& other) const {
    Moments sum;
    for (int i = 0; i < 10; ++i) sum.s_[i] = s_[i] + other.s_[i];
    return sum;
  }
  // Moments of this set without `subset` (which must be part of it).
  Moments minus(const Moments& subset) const {
    Moments rest;
    for (int i = 0; i < 10; ++i) rest.s_[i] = s_[i] - subset.s_[i];
    return rest;
  }
  double count() const { return s_[0]; }
  Eigen::Vector3d mean() const { return Eigen::Vector3d(s_[1], s_[2], s_[3]) / s_[0]; }
  // Population covariance (divides by the count).
  SymmetricMatrix3 covariance() const;

 private:
  std::array<double, 10> s_{};
};

// Eigenvalues, largest first, clamped at zero (covariances are positive semi-definite).
// Closed form (trigonometric solution of the characteristic cubic): accurate to about 1e-8 of
// the largest eigenvalue, less than float features resolve.
Eigen::Vector3d eigenvalues_descending(const SymmetricMatrix3& m);

// The same for `count` matrices at once, written to out[0, count): vectorised across
// matrices (eight at a time), with acos, cos and sin as polynomials; equal to the
// single-matrix values up to rounding.
void eigenvalues_descending(const SymmetricMatrix3* m, int count, Eigen::Vector3d* out);

// Unit eigenvector of the smallest eigenvalue (the normal of a fitted plane); any unit vector
// when the matrix is a multiple of the identity. Sign is arbitrary.
Eigen::Vector3d smallest_eigenvector(const SymmetricMatrix3& m);
// The same when the smallest eigenvalue is already known (e.g. from a batch).
Eigen::Vector3d smallest_eigenvector(const SymmetricMatrix3& m, double smallest_eigenvalue);

}  // namespace glint::geometry
