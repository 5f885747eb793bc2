#include "geometry/neighbourhoods.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <random>
#include <set>

#include "core/error.h"
#include "geometry/kdtree.h"

namespace glint::geometry {
namespace {

// Points on a unit sphere surface with a dense cluster and a few far outliers: exercises the
// 3×3×3 block, the 5×5×5 retry and the k-d tree fallback.
PointCloud uneven_cloud() {
  std::mt19937 rng(7);
  std::normal_distribution<float> g(0.f, 1.f);
  PointCloud cloud;
  for (int i = 0; i < 6000; ++i) {
    float x = g(rng), y = g(rng), z = g(rng);
    const float r = std::sqrt(x * x + y * y + z * z);
    const float shrink = i < 1500 ? 0.05f : 1.0f;  // a dense blob
    cloud.push_back(shrink * x / r, shrink * y / r, shrink * z / r);
  }
  for (int i = 0; i < 10; ++i) cloud.push_back(5.f + i, -4.f, 3.f * i);
  return cloud;
}

// One value per point, `step` times its index: a neighbour's value tells which point it is.
std::vector<float> index_values(const PointCloud& cloud, float step) {
  std::vector<float> values(cloud.size());
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = step * float(i);
  return values;
}

float squared_distance(const PointCloud& c, std::uint32_t a, std::uint32_t b) {
  const float dx = c.x[a] - c.x[b], dy = c.y[a] - c.y[b], dz = c.z[a] - c.z[b];
  return dx * dx + dy * dy + dz * dz;
}

TEST(Neighbourhoods, EveryPrefixEqualsExactKnn) {
  const PointCloud cloud = uneven_cloud();
  const std::vector<int> sizes{64, 32, 8};  // prefixes checked
  KdTree tree(cloud);
  const KnnResult exact = tree.knn_all(sizes[0]);

  std::mutex mutex;
  std::vector<int> visits(cloud.size(), 0);
  std::size_t mismatches = 0;
  NeighbourhoodParams params;
  params.k = sizes[0];
  const NeighbourhoodStats stats =
      for_each_neighbourhood(cloud, params, [&](const Neighbourhood& nb) {
        std::size_t local_mismatch = 0;
        for (const int s : sizes) {
          // The s-th distance must equal the exact s-th distance (ties allow other indices).
          float worst = 0;
          for (int j = 0; j < s; ++j)
            worst = std::max(worst, squared_distance(cloud, nb.point, nb.indices[j]));
          const float expected = exact.squared_distances[std::size_t(nb.point) * sizes[0] + s - 1];
          if (std::abs(worst - expected) > 1e-6f * std::max(1.f, expected)) ++local_mismatch;
        }
        for (int j = 0; j < nb.size; ++j) {
          const std::uint32_t i = nb.indices[j];
          if (std::abs(nb.dx[j] - (cloud.x[i] - cloud.x[nb.point])) > 1e-6f) ++local_mismatch;
        }
        std::lock_guard<std::mutex> lock(mutex);
        ++visits[nb.point];
        mismatches += local_mismatch;
      });
  EXPECT_EQ(mismatches, 0u);
  EXPECT_TRUE(std::all_of(visits.begin(), visits.end(), [](int v) { return v == 1; }));
  EXPECT_GT(stats.fallback_queries, 0u);  // the outliers
  EXPECT_GT(stats.cells, 1u);
}

TEST(Neighbourhoods, IdenticalPointsAndTinyClouds) {
  PointCloud same;
  for (int i = 0; i < 20; ++i) same.push_back(1.f, 2.f, 3.f);
  NeighbourhoodParams params;
  params.k = 20;
  std::size_t visited = 0;
  for_each_neighbourhood(same, params, [&](const Neighbourhood& nb) {
    EXPECT_EQ(nb.dx[19], 0.f);
    ++visited;
  });
  EXPECT_EQ(visited, 20u);

  params.k = 21;
  EXPECT_THROW(for_each_neighbourhood(same, params, [](const Neighbourhood&) {}), glint::Error);
  params.k = 0;
  EXPECT_THROW(for_each_neighbourhood(same, params, [](const Neighbourhood&) {}), glint::Error);
}

TEST(Neighbourhoods, LatticesWithManyEqualDistancesComeOutSorted) {
  // Lattices put many candidates at exactly equal distances, so distance buckets hold several
  // and the counts cross the scan's 16-bucket steps: lists must still be sorted, nearest first,
  // with the exact k-th distance at every prefix.
  PointCloud plane, volume;
  for (int i = 0; i < 60; ++i)
    for (int j = 0; j < 60; ++j) plane.push_back(0.5f * float(i), 0.5f * float(j), 0.f);
  for (int i = 0; i < 14; ++i)
    for (int j = 0; j < 14; ++j)
      for (int l = 0; l < 14; ++l) volume.push_back(float(i), float(j), float(l));
  for (const PointCloud* cloud : {&plane, &volume}) {
    constexpr int k = 128;
    const KnnResult exact = KdTree(*cloud).knn_all(k);
    std::mutex mutex;
    std::size_t unsorted = 0, wrong_prefix = 0, visited = 0;
    NeighbourhoodParams params;
    params.k = k;
    for_each_neighbourhood(*cloud, params, [&](const Neighbourhood& nb) {
      std::size_t local_unsorted = 0, local_wrong = 0;
      float previous = 0;
      for (int j = 0; j < k; ++j) {
        const float d = squared_distance(*cloud, nb.point, nb.indices[j]);
        local_unsorted += d < previous;
        previous = d;
        const float expected = exact.squared_distances[std::size_t(nb.point) * k + j];
        local_wrong += std::abs(d - expected) > 1e-6f * std::max(1.f, expected);
      }
      std::lock_guard<std::mutex> lock(mutex);
      unsorted += local_unsorted;
      wrong_prefix += local_wrong;
      ++visited;
    });
    EXPECT_EQ(unsorted, 0u);
    EXPECT_EQ(wrong_prefix, 0u);
    EXPECT_EQ(visited, cloud->size());
  }
}

TEST(Neighbourhoods, KthDistancesAreTheExactKthSmallest) {
  // The contract: exactly the k-th smallest of dx² + dy² + dz² over all points (this file is
  // built without fused multiply-adds, as the pass computes them), on an uneven cloud with
  // outliers (retries and the k-d tree) and on a lattice full of equal distances.
  PointCloud lattice;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) lattice.push_back(0.5f * float(i), 0.5f * float(j), 0.f);
  for (const PointCloud& cloud : {uneven_cloud(), lattice}) {
    NeighbourhoodParams params;
    params.k = 64;
    const NeighbourhoodSearch search(cloud, params);
    for (const int k : {1, 9, kMaxSmallK}) {
      std::size_t done = 0;
      const std::vector<float> kth =
          search.kth_nearest_squared_distances(k, [&](std::size_t points) { done += points; });
      ASSERT_EQ(kth.size(), cloud.size());
      EXPECT_EQ(done, cloud.size());
      std::vector<float> all(cloud.size());
      std::size_t different = 0;
      for (std::uint32_t q = 0; q < cloud.size(); ++q) {
        for (std::uint32_t i = 0; i < cloud.size(); ++i) all[i] = squared_distance(cloud, i, q);
        std::nth_element(all.begin(), all.begin() + (k - 1), all.end());
        different += kth[q] != all[k - 1];
      }
      EXPECT_EQ(different, 0u) << "k = " << k;
    }
  }
}

TEST(Neighbourhoods, KthDistancesOfWantedPointsOnly) {
  // Every third point wanted: their entries as in the full pass (retries and the k-d tree
  // included), the others 0; a mask of another size is refused.
  const PointCloud cloud = uneven_cloud();
  NeighbourhoodParams params;
  params.k = 64;
  const NeighbourhoodSearch search(cloud, params);
  const std::vector<float> all = search.kth_nearest_squared_distances(9);
  std::vector<std::uint8_t> wanted(cloud.size(), 0);
  for (std::size_t i = 0; i < cloud.size(); i += 3) wanted[i] = 1;
  const std::vector<float> some = search.kth_nearest_squared_distances(9, {}, wanted);
  ASSERT_EQ(some.size(), cloud.size());
  std::size_t different = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    different += some[i] != (wanted[i] ? all[i] : 0.0f);
  EXPECT_EQ(different, 0u);
  wanted.pop_back();
  EXPECT_THROW(search.kth_nearest_squared_distances(9, {}, wanted), glint::Error);
}

TEST(Neighbourhoods, VisitsWantedPointsOnly) {
  // Every third point wanted: each visited once, with the neighbour distances of the full pass
  // (retries and the k-d tree included); a mask of another size is refused.
  const PointCloud cloud = uneven_cloud();
  NeighbourhoodParams params;
  params.k = 64;
  const NeighbourhoodSearch search(cloud, params);
  std::vector<std::uint8_t> wanted(cloud.size(), 0);
  for (std::size_t i = 0; i < cloud.size(); i += 3) wanted[i] = 1;
  std::vector<std::vector<float>> all(cloud.size()), some(cloud.size());
  std::vector<std::atomic<int>> visits(cloud.size());
  auto keep = [](std::vector<std::vector<float>>& lists) {
    return [&lists](const Neighbourhood& nb) {
      std::vector<float>& list = lists[nb.point];
      for (int j = 0; j < nb.size; ++j)
        list.push_back(nb.dx[j] * nb.dx[j] + nb.dy[j] * nb.dy[j] + nb.dz[j] * nb.dz[j]);
      std::sort(list.begin(), list.end());
    };
  };
  search.for_each(keep(all));
  search.for_each(
      [&](const Neighbourhood& nb) {
        ++visits[nb.point];
        keep(some)(nb);
      },
      {}, {}, wanted);
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    wrong += visits[i] != (wanted[i] ? 1 : 0) || (wanted[i] && some[i] != all[i]);
  EXPECT_EQ(wrong, 0u);
  wanted.pop_back();
  EXPECT_THROW(search.for_each([](const Neighbourhood&) {}, {}, {}, wanted), glint::Error);
}

TEST(Neighbourhoods, KthDistancesRefuseBadK) {
  PointCloud cloud;
  for (int i = 0; i < 20; ++i) cloud.push_back(float(i), 0.f, 0.f);
  NeighbourhoodParams params;
  params.k = 8;
  const NeighbourhoodSearch search(cloud, params);
  EXPECT_THROW(search.kth_nearest_squared_distances(0), glint::Error);
  EXPECT_THROW(search.kth_nearest_squared_distances(kMaxSmallK + 1), glint::Error);
  PointCloud tiny;
  for (int i = 0; i < 5; ++i) tiny.push_back(float(i), 1.f, 0.f);
  params.k = 5;
  EXPECT_THROW(NeighbourhoodSearch(tiny, params).kth_nearest_squared_distances(6), glint::Error);
  EXPECT_EQ(NeighbourhoodSearch(tiny, params).kth_nearest_squared_distances(5)[0], 16.f);
}

TEST(Neighbourhoods, CarriedValuesFollowTheirNeighbours) {
  // Every neighbour's value must be its own point's, also for the outliers' k-d tree answers.
  const PointCloud cloud = uneven_cloud();
  std::vector<float> values = index_values(cloud, 0.5f);
  const NeighbourhoodSearch search(cloud, NeighbourhoodParams{32});
  std::atomic<std::size_t> wrong{0}, visited{0};
  const NeighbourhoodStats stats = search.for_each(
      [&](const Neighbourhood& nb) {
        ASSERT_NE(nb.values, nullptr);
        std::size_t local = 0;
        for (int j = 0; j < nb.size; ++j) local += nb.values[j] != 0.5f * float(nb.indices[j]);
        wrong += local;
        ++visited;
      },
      {}, values);
  EXPECT_EQ(wrong, 0u);
  EXPECT_EQ(visited, cloud.size());
  EXPECT_GT(stats.fallback_queries, 0u);
  search.for_each([](const Neighbourhood& nb) { EXPECT_EQ(nb.values, nullptr); });
  values.pop_back();
  EXPECT_THROW(search.for_each([](const Neighbourhood&) {}, {}, values), glint::Error);
}

TEST(Neighbourhoods, KeptListsAreVisitedAgainAsTheSearchVisitedThem) {
  // Every fifth point's lists kept (outliers' k-d tree answers included), then visited from the
  // lists: the same neighbours, relative positions and carried values, bit for bit.
  const PointCloud cloud = uneven_cloud();
  std::vector<float> values = index_values(cloud, 0.25f);
  const NeighbourhoodSearch search(cloud, NeighbourhoodParams{48});
  EXPECT_EQ(search.k(), 48);
  std::vector<std::uint8_t> wanted(cloud.size(), 0);
  for (std::size_t i = 0; i < cloud.size(); i += 5) wanted[i] = 1;
  wanted.back() = 1;                // an outlier
  using List = std::vector<float>;  // dx, dy, dz, value and index of each neighbour in turn
  const auto record = [](std::vector<List>& lists) {
    return [&lists](const Neighbourhood& nb) {
      List& list = lists[nb.point];
      for (int j = 0; j < nb.size; ++j)
        list.insert(list.end(), {nb.dx[j], nb.dy[j], nb.dz[j], nb.values[j], float(nb.indices[j])});
    };
  };
  KeptNeighbourhoods kept(wanted, search.k());
  std::vector<List> searched(cloud.size()), replayed(cloud.size());
  std::mutex mutex;
  search.for_each(
      [&](const Neighbourhood& nb) {
        kept.keep(nb);
        const std::lock_guard<std::mutex> lock(mutex);
        record(searched)(nb);
      },
      {}, values, wanted);
  std::atomic<std::size_t> done{0};
  visit_kept(
      cloud, kept,
      [&](const Neighbourhood& nb) {
        const std::lock_guard<std::mutex> lock(mutex);
        record(replayed)(nb);
      },
      [&](std::size_t points) { done += points; }, values);
  EXPECT_EQ(done, kept.points.size());
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i)
    wrong += replayed[i] != searched[i] || replayed[i].empty() == bool(wanted[i]);
  EXPECT_EQ(wrong, 0u);
  // Without values none are handed out; a list of another size, a point without a place and
  // values that do not fit the cloud are refused.
  visit_kept(cloud, kept, [](const Neighbourhood& nb) { EXPECT_EQ(nb.values, nullptr); });
  Neighbourhood stranger;
  stranger.point = 1;  // not wanted
  stranger.size = search.k();
  EXPECT_THROW(kept.keep(stranger), glint::Error);
  stranger.point = 0;
  stranger.size = 8;
  EXPECT_THROW(kept.keep(stranger), glint::Error);
  values.pop_back();
  EXPECT_THROW(visit_kept(
                   cloud, kept, [](const Neighbourhood&) {}, {}, values),
               glint::Error);
}

TEST(Neighbourhoods, CellsAreSizedFromTheExactKthDistances) {
  // Clouds under 20,000 points are their own sample: the cell is half the 0.9 quantile of the
  // k-th neighbour distance of every (n / 512)-th point, the distances as a k-d tree finds them
  // (uneven: the retries and the k-d tree fallback inside; a lattice: ties everywhere).
  PointCloud lattice;
  for (int y = 0; y < 60; ++y)
    for (int x = 0; x < 70; ++x) lattice.push_back(0.5f * float(x), 0.25f * float(y), 0.f);
  for (const PointCloud& cloud : {uneven_cloud(), lattice}) {
    for (const int k : {16, 64, 128}) {
      const KdTree tree(cloud);
      const std::size_t queries = 512;
      std::vector<double> radii;
      std::vector<std::uint32_t> indices(k);
      std::vector<float> distances(k);
      for (std::size_t q = 0; q < queries; ++q) {
        const std::size_t i = q * cloud.size() / queries;
        const float point[3] = {cloud.x[i], cloud.y[i], cloud.z[i]};
        tree.knn(point, k, indices.data(), distances.data());
        radii.push_back(std::sqrt(double(distances[k - 1])));
      }
      std::nth_element(radii.begin(), radii.begin() + 459, radii.end());  // 0.9 · 511
      const NeighbourhoodStats stats =
          NeighbourhoodSearch(cloud, NeighbourhoodParams{k}).for_each([](const Neighbourhood&) {});
      EXPECT_EQ(stats.cell_size, radii[459] / 2) << cloud.size() << " points, k = " << k;
    }
  }
}

}  // namespace
}  // namespace glint::geometry
