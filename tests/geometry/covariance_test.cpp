#include "geometry/covariance.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <random>
#include <vector>

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

TEST(Covariance, BatchMatchesSingleMatricesAcrossLaneChunks) {
  // 13 matrices: one full chunk of eight lanes and a partial one; eigenvalue patterns that put
  // the cubic's acos argument at -1 (a plane: two equal largest), +1 (a line: two equal
  // smallest), 0 and in between.
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0, 1);
  const Eigen::Vector3d patterns[] = {{1, 1, 0},       {1, 0, 0}, {1, 0.5, 0},     {2, 1, 0.5},
                                      {1, 1e-3, 1e-9}, {3, 3, 3}, {1, 0.999, 1e-4}};
  std::vector<SymmetricMatrix3> matrices;
  std::vector<Eigen::Vector3d> expected;
  for (int i = 0; i < 13; ++i) {
    const Eigen::Matrix3d q =
        Eigen::Quaterniond(g(rng), g(rng), g(rng), g(rng)).normalized().toRotationMatrix();
    const Eigen::Vector3d values = patterns[i % 7] * std::pow(10.0, i % 5 - 2);
    matrices.push_back(from_eigen(q * values.asDiagonal() * q.transpose()));
    expected.push_back(values);
  }
  std::vector<Eigen::Vector3d> batch(matrices.size());
  eigenvalues_descending(matrices.data(), int(matrices.size()), batch.data());
  for (std::size_t i = 0; i < matrices.size(); ++i) {
    const double largest = expected[i][0];
    const Eigen::Vector3d single = eigenvalues_descending(matrices[i]);
    for (int j = 0; j < 3; ++j) {
      EXPECT_NEAR(batch[i][j], expected[i][j], 1e-7 * largest) << "matrix " << i << ", " << j;
      // Equal eigenvalues make the trigonometric form sensitive to rounding (~1e-8, see above),
      // and the batch may round differently (fused multiply-adds in its vector clone).
      EXPECT_NEAR(batch[i][j], single[j], 1e-7 * largest) << "matrix " << i << ", " << j;
    }
  }
}

TEST(Covariance, BatchIsExactOnDiagonalMatrices) {
  // Distinct eigenvalues and no rotation: the polynomial acos, cos and sin alone decide the
  // error (equal eigenvalues cost the trigonometric form ~1e-8, as above).
  const Eigen::Vector3d cases[] = {{4, 2, 1}, {3, 2, 0}, {1, 0.25, 0.0625}, {10, 9, 0.5}};
  for (const Eigen::Vector3d& values : cases) {
    const SymmetricMatrix3 m{values[2], 0, 0, values[0], 0, values[1]};
    Eigen::Vector3d closed;
    eigenvalues_descending(&m, 1, &closed);
    EXPECT_NEAR((closed - values).norm(), 0.0, 1e-13 * values[0]) << values.transpose();
  }
}

}  // namespace
}  // namespace glint::geometry
