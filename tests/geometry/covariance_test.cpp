#include "geometry/covariance.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>

namespace glint::geometry {
namespace {

SymmetricMatrix3 from_eigen(const Eigen::Matrix3d& a) {
  return {a(0, 0), a(0, 1), a(0, 2), a(1, 1), a(1, 2), a(2, 2)};
}

TEST(Covariance, ClosedFormMatchesIterativeSolver) {
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0, 1);
  for (int trial = 0; trial < 200; ++trial) {
    // Random rotation times eigenvalues spanning several orders of magnitude (planes, lines).
    const Eigen::Matrix3d q =
        Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
    const Eigen::Vector3d values(1.0, std::pow(10.0, -3 * (trial % 3)), 1e-9 * (trial % 2));
    const Eigen::Matrix3d a = q * values.asDiagonal() * q.transpose();
    const Eigen::Vector3d closed = eigenvalues_descending(from_eigen(a));
    // The trigonometric form is accurate to ~1e-8 of the largest eigenvalue (worst for a
    // double eigenvalue): ample for float features.
    EXPECT_NEAR(closed[0], 1.0, 1e-7);
    EXPECT_NEAR(closed[1], values[1], 1e-7);
    EXPECT_NEAR(closed[2], values[2], 1e-7);
    const Eigen::Vector3d normal = smallest_eigenvector(from_eigen(a));
    EXPECT_NEAR(std::abs(normal.dot(q.col(2))), 1.0, 1e-6) << "trial " << trial;
  }
}

TEST(Covariance, DegenerateMatrices) {
  EXPECT_EQ(eigenvalues_descending({}), Eigen::Vector3d::Zero());
  EXPECT_NEAR(smallest_eigenvector({}).norm(), 1.0, 1e-12);
  const SymmetricMatrix3 line{1, 0, 0, 0, 0, 0};  // all variance along x
  EXPECT_NEAR(smallest_eigenvector(line).x(), 0.0, 1e-12);
  EXPECT_NEAR(smallest_eigenvector(line).norm(), 1.0, 1e-12);
}

TEST(Covariance, MomentsOfSubsetsSubtract) {
  Moments all, first;
  const double points[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 2, 0}, {1, 2, 4}};
  for (int i = 0; i < 4; ++i) {
    all.add(points[i][0], points[i][1], points[i][2]);
    first.add_weighted(points[i][0], points[i][1], points[i][2], i < 2 ? 1.0 : 0.0);
  }
  const Moments rest = all.minus(first);
  EXPECT_EQ(rest.count(), 2.0);
  EXPECT_TRUE(rest.mean().isApprox(Eigen::Vector3d(0.5, 2, 2)));
  const SymmetricMatrix3 c = rest.covariance();
  EXPECT_DOUBLE_EQ(c.xx, 0.25);
  EXPECT_DOUBLE_EQ(c.zz, 4.0);
  EXPECT_DOUBLE_EQ(c.xz, 1.0);
  EXPECT_DOUBLE_EQ(c.yy, 0.0);
}

}  // namespace
}  // namespace glint::geometry
