// Queued rays (fusion/ray_queue.h) against the march of one ray alone, through an analytic TSDF
// with empty cells of blocks between its surfaces and empty space around them.
#include "fusion/ray_queue.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "fusion_test_support.h"

namespace glint::fusion {
namespace {

// Two spheres 1.2 m apart, so most cells of blocks between them hold none.
double two_spheres(const Eigen::Vector3d& p) {
  return std::min((p - Eigen::Vector3d(-0.6, 0, 0)).norm() - 0.25,
                  (p - Eigen::Vector3d(0.6, 0.1, 0.2)).norm() - 0.3);
}

MarchEnd march_alone(const TsdfVolume& volume, const Eigen::Vector3f& origin,
                     const Eigen::Vector3f& direction, float t_max) {
  TsdfSampler sampler(volume);  // no occupancy: the hash alone, one block at a time
  RayMarch march(direction, t_max, float(volume.params().voxel_size_m));
  march.start(0);
  while (march.step(sampler, origin, direction)) {
  }
  return march.end();
}

TEST(RayQueue, MarchesEveryRayAsARayAloneWould) {
  VolumeParams params;
  params.voxel_size_m = 0.01;
  params.block_capacity = 40000;
  TsdfVolume volume(params);
  test::fill_analytic(volume, two_spheres, 1.2, 0.04);
  const BlockOccupancy occupancy(volume);
  RayQueue queue(volume, &occupancy);

  // Rays from around the spheres and from metres outside the volume's blocks, some aimed at a
  // sphere, some anywhere; queued in two marches.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> uniform(-1, 1);
  std::vector<float> t_max;
  for (int batch = 0; batch < 2; ++batch) {
    for (int i = 0; i < 150; ++i) {
      const float reach = i % 3 == 0 ? 6.0f : 1.0f;
      const Eigen::Vector3f origin(reach * uniform(rng), reach * uniform(rng),
                                   reach * uniform(rng));
      Eigen::Vector3f direction(uniform(rng), uniform(rng), uniform(rng));
      if (i % 2 == 0) direction = Eigen::Vector3f(i % 4 == 0 ? -0.6f : 0.6f, 0, 0) - origin;
      if (direction.norm() < 1e-3f) continue;
      queue.add(origin, direction.normalized(), i % 5 == 0 ? 0.5f : 12.0f);
      t_max.push_back(i % 5 == 0 ? 0.5f : 12.0f);
    }
    queue.march();
  }

  int hits = 0, misses = 0;
  for (int r = 0; r < queue.size(); ++r) {
    const MarchEnd alone =
        march_alone(volume, queue.origin(r), queue.direction(r), t_max[std::size_t(r)]);
    const MarchEnd& queued = queue.end(r);
    ASSERT_EQ(queued.back_face, alone.back_face) << "ray " << r;
    if (queued.t > 0) {
      // Beside an empty region the queue's march skips to its end where the lone one steps a
      // block at a time: both find the same crossing, up to where their samples fell.
      ASSERT_NEAR(queued.t, alone.t, 0.012f) << "ray " << r;
      const Eigen::Vector3f hit = queue.origin(r) + queue.direction(r) * queued.t;
      EXPECT_LT(std::abs(two_spheres(hit.cast<double>())), 0.01) << "ray " << r;
      ++hits;
    } else {
      ASSERT_EQ(alone.t, 0.0f) << "ray " << r;
      misses += !queued.back_face;
    }
  }
  EXPECT_GT(hits, 100);
  EXPECT_GT(misses, 50);

  queue.clear();
  EXPECT_EQ(queue.size(), 0);
}

}  // namespace
}  // namespace glint::fusion
