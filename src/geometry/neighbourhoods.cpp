#include "geometry/neighbourhoods.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_sort.h>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <mutex>
#include <numbers>
#include <random>
#include <span>
#include <string>
#include <utility>

#include "core/cpu_level.h"
#include "core/error.h"
#include "core/parallel.h"
#include "geometry/kdtree.h"

namespace glint::geometry {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();
// Cells per typical k-th neighbour distance. A query's candidates are the block of
// (2·kBlockRadius + 1)³ cells around its cell; finer cells fit that block closer to the
// neighbourhood's ball (fewer candidates) at the price of more cell look-ups; 2 is the
// fastest on large clouds (docs/decisions.md).
constexpr int kBlockRadius = 2;
// Queries whose k-th neighbour lies outside their block retry on a block of this radius.
constexpr int kRetryBlockRadius = 2 * kBlockRadius;

// Uniform grid over the cloud with points stored cell by cell (structure of arrays). Cells
// are sorted by (x, y, z) index, so each column of cells along z is a contiguous run of cells
// and its points a contiguous run of slots.
struct Grid {
  double cell = 1.0;
  double origin[3] = {0, 0, 0};
  std::int64_t dims[3] = {1, 1, 1};
  std::vector<std::uint32_t> cell_begin;   // cells + 1 offsets into the sorted arrays
  std::vector<std::uint64_t> cell_column;  // column key (x, y index) per cell
  std::vector<std::int32_t> cell_z;        // z index per cell (binary search within a column)
  std::vector<float> xs, ys, zs;           // positions in cell order
  std::vector<std::uint32_t> original;     // cloud index of each sorted slot
  // Open-addressing hash: column key -> its first cell and one past its last.
  std::vector<std::uint64_t> table_keys;
  std::vector<std::uint32_t> table_first, table_end;
  std::uint64_t table_mask = 0;

  std::uint64_t key(std::int64_t ix, std::int64_t iy, std::int64_t iz) const {
    return static_cast<std::uint64_t>((ix * dims[1] + iy) * dims[2] + iz);
  }
  std::uint64_t column_key(std::int64_t ix, std::int64_t iy) const {
    return static_cast<std::uint64_t>(ix * dims[1] + iy);
  }
  std::int64_t coordinate(float value, int axis) const {
    const auto c = static_cast<std::int64_t>(std::floor((value - origin[axis]) / cell));
    return std::clamp<std::int64_t>(c, 0, dims[axis] - 1);
  }
  static std::uint64_t hash(std::uint64_t key) { return (key * 0x9E3779B97F4A7C15ull) >> 17; }
  // Cells [first, end) of a column; first == end when the column is empty.
  void column(std::uint64_t key, std::uint32_t& first, std::uint32_t& end) const {
    for (std::uint64_t slot = hash(key) & table_mask;; slot = (slot + 1) & table_mask) {
      if (table_keys[slot] == key) {
        first = table_first[slot], end = table_end[slot];
        return;
      }
      if (table_keys[slot] == kEmpty) {
        first = end = 0;
        return;
      }
    }
  }
  static constexpr std::uint64_t kEmpty = std::numeric_limits<std::uint64_t>::max();
};

double quantile(std::vector<double> values, double q) {
  const auto at = static_cast<std::size_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + at, values.end());
  return values[at];
}

// A first cell size for a grid over `cloud` that answers k nearest neighbours: the k-th
// neighbour distance if the points covered the surface of their bounding box evenly. Only speed
// depends on it (queries are exact whatever the cell).
double surface_guess(const PointCloud& cloud, int k) {
  double extent[3];
  const std::vector<float>* axes[3] = {&cloud.x, &cloud.y, &cloud.z};
  for (int a = 0; a < 3; ++a) {
    const auto [low, high] = std::minmax_element(axes[a]->begin(), axes[a]->end());
    extent[a] = double(*high) - double(*low);
  }
  const double area = 2.0 * (extent[0] * extent[1] + extent[1] * extent[2] + extent[2] * extent[0]);
  const double n = double(cloud.size());
  // Collinear points: the k-th neighbour lies about k / n of the line away.
  const double guess = area > 0 ? std::sqrt(area * double(k) / (std::numbers::pi * n))
                                : std::max({extent[0], extent[1], extent[2]}) * double(k) / n;
  // Coincident points (and non-finite ones, which the callers refuse) get any positive size: a
  // size of 0 would ask for this estimate again.
  return std::isfinite(guess) && guess > 0 ? guess : 1.0;
}

// A high quantile of the k-th neighbour distance over a subsample whose neighbour count is scaled
// by the sampling rate (surface-like density assumed); the grid cells are sized from it. The
// sample's k-th distances are exact (a grid over the sample sized by surface_guess), computed as
// (x_j - x_q)² + (y_j - y_q)² + (z_j - z_q)² in float like a k-d tree's, so the cell size does not
// depend on how they were found.
double high_kth_distance(const PointCloud& cloud, int k) {
  const std::size_t n = cloud.size();
  const std::size_t m = std::min<std::size_t>(n, std::max<std::size_t>(20000, n / 8));
  // A seeded random subsample: a fixed stride could alias with the file's point order.
  std::mt19937_64 rng(12345);
  std::uniform_int_distribution<std::size_t> pick(0, n - 1);
  PointCloud sample;
  sample.reserve(m);
  for (std::size_t j = 0; j < m; ++j) {
    const std::size_t i = m == n ? j : pick(rng);
    sample.push_back(cloud.x[i], cloud.y[i], cloud.z[i]);
  }
  const int k_sample = static_cast<int>(std::clamp<double>(
      std::round(double(k) * double(m) / double(n)), 4.0, double(std::min<std::size_t>(m, k))));
  // The sample's k_sample-th neighbour sits at about the full cloud's (k_sample·n/m)-th; for a
  // surface the radius grows with the square root of the count.
  const double correction = std::sqrt(double(k) * double(m) / (double(n) * double(k_sample)));
  const std::size_t queries = std::min<std::size_t>(m, 512);
  std::vector<std::uint8_t> queried(m, 0);
  for (std::size_t q = 0; q < queries; ++q) queried[q * m / queries] = 1;
  NeighbourhoodParams params;
  params.k = k_sample;
  params.cell_size = surface_guess(sample, k_sample);
  const std::vector<float> kth =
      NeighbourhoodSearch(sample, params).kth_nearest_squared_distances(k_sample, {}, queried);
  std::vector<double> radii(queries);
  for (std::size_t q = 0; q < queries; ++q)
    radii[q] = std::sqrt(double(kth[q * m / queries])) * correction;
  return quantile(std::move(radii), 0.9);
}

Grid build_grid(const PointCloud& cloud, double cell_size) {
  Grid grid;
  const std::size_t n = cloud.size();
  float lo[3] = {kInfinity, kInfinity, kInfinity};
  float hi[3] = {-kInfinity, -kInfinity, -kInfinity};
  const std::vector<float>* axes[3] = {&cloud.x, &cloud.y, &cloud.z};
  for (int a = 0; a < 3; ++a) {
    const auto [min_it, max_it] = std::minmax_element(axes[a]->begin(), axes[a]->end());
    lo[a] = *min_it;
    hi[a] = *max_it;
  }
  const double extent =
      std::max({double(hi[0]) - lo[0], double(hi[1]) - lo[1], double(hi[2]) - lo[2]});
  if (!(cell_size > 0.0) || !std::isfinite(cell_size)) cell_size = extent > 0 ? extent : 1.0;
  // Keep the key space inside 64 bits: at most 2^20 cells per axis.
  cell_size = std::max(cell_size, extent / double(1 << 20));
  grid.cell = cell_size;
  for (int a = 0; a < 3; ++a) {
    grid.origin[a] = lo[a];
    grid.dims[a] = static_cast<std::int64_t>(std::floor((double(hi[a]) - lo[a]) / cell_size)) + 1;
  }

  std::vector<std::pair<std::uint64_t, std::uint32_t>> slots(n);
  parallel_for(n, [&](std::size_t i) {
    slots[i] = {grid.key(grid.coordinate(cloud.x[i], 0), grid.coordinate(cloud.y[i], 1),
                         grid.coordinate(cloud.z[i], 2)),
                static_cast<std::uint32_t>(i)};
  });
  tbb::parallel_sort(slots.begin(), slots.end());

  grid.xs.resize(n);
  grid.ys.resize(n);
  grid.zs.resize(n);
  grid.original.resize(n);
  parallel_for(n, [&](std::size_t s) {
    const std::uint32_t i = slots[s].second;
    grid.xs[s] = cloud.x[i];
    grid.ys[s] = cloud.y[i];
    grid.zs[s] = cloud.z[i];
    grid.original[s] = i;
  });
  std::vector<std::uint64_t> cell_keys;
  for (std::size_t s = 0; s < n; ++s) {
    if (s == 0 || slots[s].first != slots[s - 1].first) {
      cell_keys.push_back(slots[s].first);
      grid.cell_begin.push_back(static_cast<std::uint32_t>(s));
    }
  }
  grid.cell_begin.push_back(static_cast<std::uint32_t>(n));

  const std::size_t cells = cell_keys.size();
  grid.cell_column.resize(cells);
  grid.cell_z.resize(cells);
  const auto depth = static_cast<std::uint64_t>(grid.dims[2]);
  for (std::size_t c = 0; c < cells; ++c) {
    grid.cell_column[c] = cell_keys[c] / depth;
    grid.cell_z[c] = static_cast<std::int32_t>(cell_keys[c] % depth);
  }
  std::uint64_t capacity = 16;
  while (capacity < 2 * cells) capacity *= 2;
  grid.table_mask = capacity - 1;
  grid.table_keys.assign(capacity, Grid::kEmpty);
  grid.table_first.assign(capacity, 0);
  grid.table_end.assign(capacity, 0);
  for (std::size_t c = 0; c < cells;) {
    const std::uint64_t column = grid.cell_column[c];
    std::size_t end = c + 1;
    while (end < cells && grid.cell_column[end] == column) ++end;
    std::uint64_t slot = Grid::hash(column) & grid.table_mask;
    while (grid.table_keys[slot] != Grid::kEmpty) slot = (slot + 1) & grid.table_mask;
    grid.table_keys[slot] = column;
    grid.table_first[slot] = static_cast<std::uint32_t>(c);
    grid.table_end[slot] = static_cast<std::uint32_t>(end);
    c = end;
  }
  return grid;
}

// Per-thread working memory, reused across cells (no allocation per point).
struct Scratch {
  std::vector<float> cx, cy, cz;      // gathered candidates
  std::vector<std::uint32_t> cindex;  // their index in the cloud
  std::vector<float> cvalue;          // their value, when for_each carries values
  std::vector<float> distances;       // squared distance of each candidate to the query
  std::vector<std::uint64_t> ranked;  // (squared distance bits << 32) | candidate
  float previous_kth = 0;             // k-th squared distance of the previous query
  // Distance buckets of the selection: with the AVX-512 scan about three per candidate (the
  // range holds ~1.25 k of them), so most hold one and the insertion sort seldom moves
  // anything; a serial scan over that many would cost more than it saves.
  static constexpr int kBucketsAvx512 = 512;
  static constexpr int kBuckets = 128;
  std::vector<std::uint32_t> within;     // candidates inside the bucket range
  std::vector<float> within_distance;    // their squared distances
  std::vector<std::uint16_t> bucket_of;  // and buckets
  std::array<std::uint32_t, kBucketsAvx512> bucket_start{};
  std::vector<float> dx, dy, dz;  // accepted neighbourhood, relative to the query
  std::vector<std::uint32_t> indices;
  std::vector<float> values;         // and its values, when carried
  std::vector<std::uint32_t> retry;  // sorted slots that need a larger block
  std::vector<float> fallback_distances;
};

// Candidate block of `radius` cells around a cell: gathers its points (and their entries of
// slot_values, a value per sorted slot, when given) and returns the block's bounds (infinite
// on sides where the grid ends, since nothing lies beyond).
void gather_block(const Grid& grid, std::size_t cell, int radius, Scratch& scratch, double lower[3],
                  double upper[3], const float* slot_values = nullptr) {
  scratch.cx.clear();
  scratch.cy.clear();
  scratch.cz.clear();
  scratch.cindex.clear();
  scratch.cvalue.clear();
  const auto rows = static_cast<std::uint64_t>(grid.dims[1]);
  const std::int64_t c[3] = {static_cast<std::int64_t>(grid.cell_column[cell] / rows),
                             static_cast<std::int64_t>(grid.cell_column[cell] % rows),
                             grid.cell_z[cell]};
  std::int64_t from[3], to[3];
  for (int a = 0; a < 3; ++a) {
    from[a] = std::max<std::int64_t>(0, c[a] - radius);
    to[a] = std::min<std::int64_t>(grid.dims[a] - 1, c[a] + radius);
    lower[a] = from[a] == 0 ? -std::numeric_limits<double>::infinity()
                            : grid.origin[a] + double(from[a]) * grid.cell;
    upper[a] = to[a] == grid.dims[a] - 1 ? std::numeric_limits<double>::infinity()
                                         : grid.origin[a] + double(to[a] + 1) * grid.cell;
  }
  for (std::int64_t ix = from[0]; ix <= to[0]; ++ix) {
    for (std::int64_t iy = from[1]; iy <= to[1]; ++iy) {
      // The column's cells within [from z, to z] hold one contiguous run of points.
      std::uint32_t column_first, column_end;
      grid.column(grid.column_key(ix, iy), column_first, column_end);
      if (column_first == column_end) continue;
      const std::int32_t* z = grid.cell_z.data();
      const auto first = std::lower_bound(z + column_first, z + column_end, from[2]) - z;
      const auto last = std::upper_bound(z + first, z + column_end, to[2]) - z;
      if (first == last) continue;
      const std::uint32_t begin = grid.cell_begin[first], end = grid.cell_begin[last];
      scratch.cx.insert(scratch.cx.end(), grid.xs.begin() + begin, grid.xs.begin() + end);
      scratch.cy.insert(scratch.cy.end(), grid.ys.begin() + begin, grid.ys.begin() + end);
      scratch.cz.insert(scratch.cz.end(), grid.zs.begin() + begin, grid.zs.begin() + end);
      scratch.cindex.insert(scratch.cindex.end(), grid.original.begin() + begin,
                            grid.original.begin() + end);
      if (slot_values)
        scratch.cvalue.insert(scratch.cvalue.end(), slot_values + begin, slot_values + end);
    }
  }
}

// Distance from a query to the nearest side of its candidate block: nothing outside the block
// is nearer.
inline double guaranteed_radius(float qx, float qy, float qz, const double lower[3],
                                const double upper[3]) {
  return std::min(
      {qx - lower[0], upper[0] - qx, qy - lower[1], upper[1] - qy, qz - lower[2], upper[2] - qz});
}

// Sort key of a candidate: squared distance bits (monotone for non-negative floats) above the
// candidate's position in the block.
inline std::uint64_t pack(float squared_distance, std::size_t candidate) {
  return (std::uint64_t(std::bit_cast<std::uint32_t>(squared_distance)) << 32) | candidate;
}

// Candidates compacted per step by the AVX-512 path (it may write this many past the last).
constexpr std::size_t kCompactLanes = 16;

// Appends to within[kept...] the indices j in [first, count) with distances[j] <= limit, and
// their distances to within_distance[kept...] (branch-free); returns the new count.
inline std::size_t compact_within(const float* distances, std::size_t first, std::size_t count,
                                  float limit, std::uint32_t* within, float* within_distance,
                                  std::size_t kept) {
  for (std::size_t j = first; j < count; ++j) {
    within[kept] = static_cast<std::uint32_t>(j);
    within_distance[kept] = distances[j];
    kept += distances[j] <= limit;
  }
  return kept;
}

#if defined(__x86_64__)
// The same for whole steps of sixteen candidates, compressed in a register (the memory form of
// vpcompressd is microcoded on AMD Zen 4); `scanned` gets where the steps ended.
[[gnu::target("arch=x86-64-v4")]] inline std::size_t compact_steps_avx512(
    const float* distances, std::size_t count, float limit, std::uint32_t* within,
    float* within_distance, std::size_t& scanned) {
  const __m512 bound = _mm512_set1_ps(limit);
  const __m512i step = _mm512_set1_epi32(int(kCompactLanes));
  __m512i index = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  std::size_t kept = 0, j = 0;
  for (; j + kCompactLanes <= count; j += kCompactLanes) {
    const __m512 distance = _mm512_loadu_ps(distances + j);
    const __mmask16 inside = _mm512_cmp_ps_mask(distance, bound, _CMP_LE_OQ);
    _mm512_storeu_si512(within + kept, _mm512_maskz_compress_epi32(inside, index));
    _mm512_storeu_ps(within_distance + kept, _mm512_maskz_compress_ps(inside, distance));
    kept += std::popcount(static_cast<unsigned>(inside));
    index = _mm512_add_epi32(index, step);
  }
  scanned = j;
  return kept;
}
#endif

// Turns bucket counts into each bucket's first position (a serial scan; the AVX-512 path has
// its own below).
inline void exclusive_scan_buckets(std::uint32_t* counts) {
  std::uint32_t offset = 0;
  for (int b = 0; b < Scratch::kBuckets; ++b) offset += std::exchange(counts[b], offset);
}

#if defined(__x86_64__)
static_assert(Scratch::kBucketsAvx512 % 16 == 0);
// Sixteen buckets at a time: an in-register inclusive scan (shifts by 1, 2, 4 and 8 lanes),
// minus the counts themselves, plus the total of the buckets before.
[[gnu::target("arch=x86-64-v4")]] inline void exclusive_scan_buckets_avx512(std::uint32_t* counts) {
  const __m512i zero = _mm512_setzero_si512();
  const __m512i last_lane = _mm512_set1_epi32(15);
  __m512i carry = zero;
  for (int b = 0; b < Scratch::kBucketsAvx512; b += 16) {
    const __m512i count = _mm512_loadu_si512(counts + b);
    __m512i sum = _mm512_add_epi32(count, _mm512_maskz_alignr_epi32(0xFFFF, count, zero, 15));
    sum = _mm512_add_epi32(sum, _mm512_maskz_alignr_epi32(0xFFFF, sum, zero, 14));
    sum = _mm512_add_epi32(sum, _mm512_maskz_alignr_epi32(0xFFFF, sum, zero, 12));
    sum = _mm512_add_epi32(sum, _mm512_maskz_alignr_epi32(0xFFFF, sum, zero, 8));
    sum = _mm512_add_epi32(sum, carry);
    _mm512_storeu_si512(counts + b, _mm512_sub_epi32(sum, count));
    carry = _mm512_maskz_permutexvar_epi32(0xFFFF, last_lane, sum);
  }
}
#endif

// Writes the candidates with squared distance <= limit to `sorted`, the first k of them in
// increasing order, and returns how many there are. They are first compacted,
// then counting-sorted into buckets of equal squared distance, and an insertion sort fixes the
// order inside each bucket.
template <bool kAvx512>
std::size_t bucket_sort_within(const float* distances, std::size_t count, float limit, int k,
                               Scratch& scratch, std::uint64_t* sorted) {
  scratch.within.resize(count + kCompactLanes);
  scratch.within_distance.resize(count + kCompactLanes);
  std::uint32_t* within = scratch.within.data();
  float* within_distance = scratch.within_distance.data();
  std::size_t kept = 0, scanned = 0;
#if defined(__x86_64__)
  if constexpr (kAvx512)
    kept = compact_steps_avx512(distances, count, limit, within, within_distance, scanned);
#endif
  kept = compact_within(distances, scanned, count, limit, within, within_distance, kept);
  constexpr int buckets = kAvx512 ? Scratch::kBucketsAvx512 : Scratch::kBuckets;
  std::uint32_t* start = scratch.bucket_start.data();
  std::fill(start, start + buckets, 0u);
  scratch.bucket_of.resize(kept);
  std::uint16_t* bucket_of = scratch.bucket_of.data();
  const float to_bucket = float(buckets) / limit;
  // Two loops: the first runs in vector lanes, the second is the serial count.
  for (std::size_t i = 0; i < kept; ++i)
    bucket_of[i] =
        static_cast<std::uint16_t>(std::min(int(within_distance[i] * to_bucket), buckets - 1));
  for (std::size_t i = 0; i < kept; ++i) ++start[bucket_of[i]];
#if defined(__x86_64__)
  if constexpr (kAvx512) exclusive_scan_buckets_avx512(start);
#endif
  if constexpr (!kAvx512) exclusive_scan_buckets(start);
  // Scattering advances each bucket's start to its end.
  for (std::size_t i = 0; i < kept; ++i)
    sorted[start[bucket_of[i]]++] = pack(within_distance[i], within[i]);
  // Only the first k need their order: sort up to the end of the bucket holding position
  // k - 1 (later buckets hold only farther candidates).
  std::size_t end = kept;
  if (kept >= static_cast<std::size_t>(k))
    end = *std::upper_bound(start, start + buckets, std::uint32_t(k - 1));
  for (std::size_t i = 1; i < end; ++i) {
    const std::uint64_t value = sorted[i];
    std::size_t j = i;
    for (; j > 0 && sorted[j - 1] > value; --j) sorted[j] = sorted[j - 1];
    sorted[j] = value;
  }
  return kept;
}

// Selects the k nearest candidates of the query, nearest first; false when the k-th lies farther
// than the block's guaranteed radius (then a candidate outside the block could be closer).
template <bool kAvx512>
bool select_from_block(const Grid& grid, std::uint32_t slot, const double lower[3],
                       const double upper[3], int k, Scratch& scratch) {
  const std::size_t count = scratch.cx.size();
  if (count < static_cast<std::size_t>(k)) return false;
  const float qx = grid.xs[slot], qy = grid.ys[slot], qz = grid.zs[slot];
  const double guaranteed = guaranteed_radius(qx, qy, qz, lower, upper);
  scratch.distances.resize(count);
  scratch.ranked.resize(count);
  const float* cx = scratch.cx.data();
  const float* cy = scratch.cy.data();
  const float* cz = scratch.cz.data();
  float* distances = scratch.distances.data();
  for (std::size_t j = 0; j < count; ++j) {
    const float ex = cx[j] - qx, ey = cy[j] - qy, ez = cz[j] - qz;
    distances[j] = ex * ex + ey * ey + ez * ez;
  }
  // Neighbouring queries have similar k-th distances: candidates within a margin of the
  // previous one are bucket-sorted (buckets of equal squared distance hold about equally many
  // points on a surface), which leaves only a short insertion sort; the list comes out fully
  // ordered, so every nested size is a prefix.
  std::uint64_t* ranked = scratch.ranked.data();
  std::size_t kept = 0;
  if (scratch.previous_kth > 0) {
    kept = bucket_sort_within<kAvx512>(distances, count, scratch.previous_kth * 1.25f, k, scratch,
                                       ranked);
  }
  if (kept < static_cast<std::size_t>(k)) {
    for (std::size_t j = 0; j < count; ++j) ranked[j] = pack(distances[j], j);
    std::nth_element(ranked, ranked + (k - 1), ranked + count);
    std::sort(ranked, ranked + k);
  }
  const float kth = std::bit_cast<float>(static_cast<std::uint32_t>(ranked[k - 1] >> 32));
  scratch.previous_kth = kth;
  if (double(kth) > guaranteed * guaranteed * (1.0 - 1e-6)) return false;
  for (int j = 0; j < k; ++j) {
    const auto candidate = static_cast<std::uint32_t>(ranked[j]);
    scratch.dx[j] = cx[candidate] - qx;
    scratch.dy[j] = cy[candidate] - qy;
    scratch.dz[j] = cz[candidate] - qz;
    scratch.indices[j] = scratch.cindex[candidate];
  }
  if (!scratch.cvalue.empty())
    for (int j = 0; j < k; ++j)
      scratch.values[j] = scratch.cvalue[static_cast<std::uint32_t>(ranked[j])];
  return true;
}

using SelectKernel = bool (*)(const Grid&, std::uint32_t, const double*, const double*, int,
                              Scratch&);

[[gnu::flatten]] bool select_from_block_baseline(const Grid& grid, std::uint32_t slot,
                                                 const double lower[3], const double upper[3],
                                                 int k, Scratch& scratch) {
  return select_from_block<false>(grid, slot, lower, upper, k, scratch);
}
#if defined(__x86_64__)
// The same code in eight-lane vectors; fused multiply-adds round the squared distances
// differently, which can only reorder neighbours at equal distance.
[[gnu::target("arch=x86-64-v3"), gnu::flatten]] bool select_from_block_x86_64_v3(
    const Grid& grid, std::uint32_t slot, const double lower[3], const double upper[3], int k,
    Scratch& scratch) {
  return select_from_block<false>(grid, slot, lower, upper, k, scratch);
}
// ... and with the AVX-512 compaction.
[[gnu::target("arch=x86-64-v4"), gnu::flatten]] bool select_from_block_x86_64_v4(
    const Grid& grid, std::uint32_t slot, const double lower[3], const double upper[3], int k,
    Scratch& scratch) {
  return select_from_block<true>(grid, slot, lower, upper, k, scratch);
}
#endif

SelectKernel select_kernel() {
#if defined(__x86_64__)
  if (cpu_has_x86_64_v4()) return select_from_block_x86_64_v4;
  if (cpu_has_x86_64_v3()) return select_from_block_x86_64_v3;
#endif
  return select_from_block_baseline;
}

}  // namespace

struct NeighbourhoodSearch::State {
  const PointCloud& cloud;
  int k;
  Grid grid;
  std::once_flag tree_built;
  std::unique_ptr<KdTree> tree;

  // For the sparse regions and outliers that no block answers; built on first use.
  const KdTree& kd_tree() {
    std::call_once(tree_built, [&] { tree = std::make_unique<KdTree>(cloud); });
    return *tree;
  }
};

NeighbourhoodSearch::NeighbourhoodSearch(const PointCloud& cloud,
                                         const NeighbourhoodParams& params) {
  const int k = params.k;
  if (k < 1) throw Error("", "neighbourhood search", "k must be at least 1");
  if (cloud.size() < static_cast<std::size_t>(k)) {
    throw Error("", "neighbourhood search",
                "the cloud has " + std::to_string(cloud.size()) +
                    " points, fewer than k = " + std::to_string(k));
  }
  const double cell =
      params.cell_size > 0 ? params.cell_size : high_kth_distance(cloud, k) / kBlockRadius;
  state_.reset(new State{cloud, k, build_grid(cloud, cell), {}, {}});
}

NeighbourhoodSearch::~NeighbourhoodSearch() = default;

int NeighbourhoodSearch::k() const { return state_->k; }

namespace {

// Throws when a mask of wanted points (empty: every point) does not fit the cloud.
void check_wanted(std::span<const std::uint8_t> wanted, std::size_t points, const char* element) {
  if (!wanted.empty() && wanted.size() != points) {
    throw Error("", element,
                "the mask of wanted points has " + std::to_string(wanted.size()) + " entries for " +
                    std::to_string(points) + " points");
  }
}

// Whether the point in `slot` is wanted, and whether any point of slots [begin, end) is.
bool slot_wanted(const Grid& grid, std::span<const std::uint8_t> wanted, std::uint32_t slot) {
  return wanted.empty() || wanted[grid.original[slot]] != 0;
}
bool any_slot_wanted(const Grid& grid, std::span<const std::uint8_t> wanted, std::uint32_t begin,
                     std::uint32_t end) {
  for (std::uint32_t slot = begin; slot < end; ++slot)
    if (slot_wanted(grid, wanted, slot)) return true;
  return false;
}

}  // namespace

NeighbourhoodStats NeighbourhoodSearch::for_each(
    const std::function<void(const Neighbourhood&)>& visit,
    const std::function<void(std::size_t)>& progress, std::span<const float> values,
    std::span<const std::uint8_t> wanted) const {
  const int k = state_->k;
  const Grid& grid = state_->grid;
  const std::size_t n = grid.original.size();
  if (!values.empty() && values.size() != n) {
    throw Error(
        "", "neighbourhood search",
        "has " + std::to_string(values.size()) + " values for " + std::to_string(n) + " points");
  }
  check_wanted(wanted, n, "neighbourhood search");
  // In slot order, so that a block's values are gathered with its positions (neighbours' values
  // looked up by cloud index would be cache misses).
  std::vector<float> slot_values(values.size());
  parallel_for(slot_values.size(),
               [&](std::size_t slot) { slot_values[slot] = values[grid.original[slot]]; });
  const float* carried = values.empty() ? nullptr : slot_values.data();
  NeighbourhoodStats stats;
  stats.cell_size = grid.cell;
  stats.cells = grid.cell_begin.size() - 1;

  const SelectKernel select = select_kernel();
  std::atomic<std::size_t> retried{0}, fallbacks{0};
  tbb::enumerable_thread_specific<Scratch> scratches([k] {
    Scratch s;
    s.dx.resize(k);
    s.dy.resize(k);
    s.dz.resize(k);
    s.indices.resize(k);
    s.values.resize(k);
    s.fallback_distances.resize(k);
    return s;
  });

  auto emit = [&](std::uint32_t slot, Scratch& scratch) {
    Neighbourhood neighbourhood;
    neighbourhood.point = grid.original[slot];
    neighbourhood.size = k;
    neighbourhood.dx = scratch.dx.data();
    neighbourhood.dy = scratch.dy.data();
    neighbourhood.dz = scratch.dz.data();
    neighbourhood.indices = scratch.indices.data();
    neighbourhood.values = carried ? scratch.values.data() : nullptr;
    visit(neighbourhood);
  };

  parallel_for_chunks(stats.cells, 4, [&](std::size_t first_cell, std::size_t end_cell) {
    Scratch& scratch = scratches.local();
    double lower[3], upper[3];
    std::size_t done = 0;
    for (std::size_t cell_id = first_cell; cell_id < end_cell; ++cell_id) {
      const std::uint32_t begin = grid.cell_begin[cell_id], end = grid.cell_begin[cell_id + 1];
      done += end - begin;
      if (!any_slot_wanted(grid, wanted, begin, end)) continue;
      scratch.retry.clear();
      gather_block(grid, cell_id, kBlockRadius, scratch, lower, upper, carried);
      for (std::uint32_t slot = begin; slot < end; ++slot) {
        if (!slot_wanted(grid, wanted, slot)) continue;
        if (select(grid, slot, lower, upper, k, scratch)) {
          emit(slot, scratch);
        } else {
          scratch.retry.push_back(slot);
        }
      }
      if (!scratch.retry.empty()) {
        retried += scratch.retry.size();
        gather_block(grid, cell_id, kRetryBlockRadius, scratch, lower, upper, carried);
        for (const std::uint32_t slot : scratch.retry) {
          if (!select(grid, slot, lower, upper, k, scratch)) {
            // Sparse region or outlier: exact k-d tree query, already sorted by distance.
            ++fallbacks;
            const float query[3] = {grid.xs[slot], grid.ys[slot], grid.zs[slot]};
            state_->kd_tree().knn(query, k, scratch.indices.data(),
                                  scratch.fallback_distances.data());
            for (int j = 0; j < k; ++j) {
              const std::uint32_t i = scratch.indices[j];
              scratch.dx[j] = state_->cloud.x[i] - query[0];
              scratch.dy[j] = state_->cloud.y[i] - query[1];
              scratch.dz[j] = state_->cloud.z[i] - query[2];
              if (carried) scratch.values[j] = values[i];
            }
          }
          emit(slot, scratch);
        }
      }
    }
    if (progress) progress(done);
  });
  stats.retried_queries = retried;
  stats.fallback_queries = fallbacks;
  return stats;
}

namespace {

// Squared distances from (qx, qy, qz) to the gathered candidates. Never inlined into a kernel
// built for a later instruction set: fused multiply-adds would round them differently from
// a visitor's dx² + dy² + dz².
[[gnu::noinline]] void candidate_squared_distances(float qx, float qy, float qz, Scratch& scratch) {
  const std::size_t count = scratch.cx.size();
  scratch.distances.resize(count);
  const float* cx = scratch.cx.data();
  const float* cy = scratch.cy.data();
  const float* cz = scratch.cz.data();
  float* distances = scratch.distances.data();
  for (std::size_t j = 0; j < count; ++j) {
    const float ex = cx[j] - qx, ey = cy[j] - qy, ez = cz[j] - qz;
    distances[j] = ex * ex + ey * ey + ez * ez;
  }
}

// Pools up to this size are ranked by counting, larger ones by nth_element.
constexpr std::size_t kRankedPool = 32;

// The k-th smallest of values[0, n): the value with fewer than k smaller and at least k not
// larger, found by counting for every value (branch-free, in vector lanes).
inline float kth_smallest_by_counting(const float* values, std::size_t n, int k) {
  float kth = values[0];
  for (std::size_t i = 0; i < n; ++i) {
    const float v = values[i];
    int less = 0, not_larger = 0;
    for (std::size_t j = 0; j < n; ++j) {
      less += values[j] < v;
      not_larger += values[j] <= v;
    }
    kth = less < k && not_larger >= k ? v : kth;
  }
  return kth;
}

// The k-th smallest squared distance from (qx, qy, qz) to the gathered candidates (infinite
// when there are fewer than k). Neighbouring queries have similar k-th distances: the
// candidates within a margin of the previous one are compacted and ranked (all of them only
// when fewer than k are kept), where the bucket sort above is laid out for k ~ 128.
template <bool kAvx512>
float kth_candidate_distance(float qx, float qy, float qz, int k, Scratch& scratch) {
  const std::size_t count = scratch.cx.size();
  if (count < static_cast<std::size_t>(k)) return kInfinity;
  candidate_squared_distances(qx, qy, qz, scratch);
  float* pool = scratch.distances.data();
  std::size_t pooled = count;
  // A margin that keeps too few is widened once before the whole block is ranked.
  for (const float margin : {1.5f, 6.0f}) {
    if (!(scratch.previous_kth > 0)) break;
    scratch.within.resize(count + kCompactLanes);
    scratch.within_distance.resize(count + kCompactLanes);
    const float limit = scratch.previous_kth * margin;
    std::size_t kept = 0, scanned = 0;
#if defined(__x86_64__)
    if constexpr (kAvx512)
      kept = compact_steps_avx512(pool, count, limit, scratch.within.data(),
                                  scratch.within_distance.data(), scanned);
#endif
    kept = compact_within(pool, scanned, count, limit, scratch.within.data(),
                          scratch.within_distance.data(), kept);
    if (kept >= static_cast<std::size_t>(k)) {
      pool = scratch.within_distance.data(), pooled = kept;
      break;
    }
  }
  float kth;
  if (pooled <= kRankedPool) {
    kth = kth_smallest_by_counting(pool, pooled, k);
  } else {
    std::nth_element(pool, pool + (k - 1), pool + pooled);
    kth = pool[k - 1];
  }
  scratch.previous_kth = kth;
  return kth;
}

using KthKernel = float (*)(float, float, float, int, Scratch&);

[[gnu::flatten]] float kth_candidate_distance_baseline(float qx, float qy, float qz, int k,
                                                       Scratch& scratch) {
  return kth_candidate_distance<false>(qx, qy, qz, k, scratch);
}
#if defined(__x86_64__)
// The same with the AVX-512 compaction and counting in sixteen lanes (the distances stay
// baseline code, see candidate_squared_distances).
[[gnu::target("arch=x86-64-v4"), gnu::flatten]] float kth_candidate_distance_x86_64_v4(
    float qx, float qy, float qz, int k, Scratch& scratch) {
  return kth_candidate_distance<true>(qx, qy, qz, k, scratch);
}
#endif

KthKernel kth_kernel() {
#if defined(__x86_64__)
  if (cpu_has_x86_64_v4()) return kth_candidate_distance_x86_64_v4;
#endif
  return kth_candidate_distance_baseline;
}

}  // namespace

std::vector<float> NeighbourhoodSearch::kth_nearest_squared_distances(
    int k, const std::function<void(std::size_t)>& progress,
    std::span<const std::uint8_t> wanted) const {
  const PointCloud& cloud = state_->cloud;
  const Grid& grid = state_->grid;
  const int largest_k = std::max(kMaxSmallK, state_->k);
  if (k < 1 || k > largest_k) {
    throw Error("", "k-th neighbour distances",
                "k must be between 1 and " + std::to_string(largest_k));
  }
  if (cloud.size() < static_cast<std::size_t>(k)) {
    throw Error("", "k-th neighbour distances",
                "the cloud has " + std::to_string(cloud.size()) +
                    " points, fewer than k = " + std::to_string(k));
  }
  check_wanted(wanted, cloud.size(), "k-th neighbour distances");
  const std::size_t cells = grid.cell_begin.size() - 1;
  const KthKernel kth_candidate_distance = kth_kernel();
  std::vector<float> result(cloud.size(), 0.0f);
  tbb::enumerable_thread_specific<Scratch> scratches;
  parallel_for_chunks(cells, 16, [&](std::size_t first_cell, std::size_t end_cell) {
    Scratch& scratch = scratches.local();
    double lower[3], upper[3];
    for (std::size_t cell_id = first_cell; cell_id < end_cell; ++cell_id) {
      const std::uint32_t begin = grid.cell_begin[cell_id], end = grid.cell_begin[cell_id + 1];
      scratch.retry.clear();
      if (!any_slot_wanted(grid, wanted, begin, end)) continue;
      // The cells are sized for the larger k, so one cell around usually holds the k nearest.
      gather_block(grid, cell_id, 1, scratch, lower, upper);
      for (std::uint32_t slot = begin; slot < end; ++slot) {
        if (!slot_wanted(grid, wanted, slot)) continue;
        const float qx = grid.xs[slot], qy = grid.ys[slot], qz = grid.zs[slot];
        const float kth = kth_candidate_distance(qx, qy, qz, k, scratch);
        const double guaranteed = guaranteed_radius(qx, qy, qz, lower, upper);
        if (double(kth) <= guaranteed * guaranteed * (1.0 - 1e-6))
          result[grid.original[slot]] = kth;
        else
          scratch.retry.push_back(slot);
      }
      if (scratch.retry.empty()) continue;
      gather_block(grid, cell_id, kBlockRadius, scratch, lower, upper);
      for (const std::uint32_t slot : scratch.retry) {
        const float qx = grid.xs[slot], qy = grid.ys[slot], qz = grid.zs[slot];
        float kth = kth_candidate_distance(qx, qy, qz, k, scratch);
        const double guaranteed = guaranteed_radius(qx, qy, qz, lower, upper);
        if (double(kth) > guaranteed * guaranteed * (1.0 - 1e-6)) {
          // Sparse region or outlier: exact k-d tree query; the distance recomputed as above.
          const float query[3] = {qx, qy, qz};
          scratch.indices.resize(k);
          scratch.fallback_distances.resize(k);
          state_->kd_tree().knn(query, k, scratch.indices.data(),
                                scratch.fallback_distances.data());
          kth = 0;
          for (int j = 0; j < k; ++j) {
            const std::uint32_t i = scratch.indices[j];
            const float ex = cloud.x[i] - qx, ey = cloud.y[i] - qy, ez = cloud.z[i] - qz;
            kth = std::max(kth, ex * ex + ey * ey + ez * ez);
          }
        }
        result[grid.original[slot]] = kth;
      }
    }
    if (progress) progress(grid.cell_begin[end_cell] - grid.cell_begin[first_cell]);
  });
  return result;
}

KeptNeighbourhoods::KeptNeighbourhoods(std::span<const std::uint8_t> wanted, int k) : k(k) {
  for (std::size_t i = 0; i < wanted.size(); ++i)
    if (wanted[i]) points.push_back(static_cast<std::uint32_t>(i));
  neighbours = make_pool<std::uint32_t>(points.size() * std::size_t(k), "kept neighbourhoods");
}

void KeptNeighbourhoods::keep(const Neighbourhood& nb) {
  const auto place = std::lower_bound(points.begin(), points.end(), nb.point);
  if (nb.size != k || place == points.end() || *place != nb.point)
    throw Error("", "kept neighbourhoods",
                "point " + std::to_string(nb.point) + " with " + std::to_string(nb.size) +
                    " neighbours has no place among the kept lists of " + std::to_string(k));
  std::copy_n(nb.indices, k, neighbours.get() + (place - points.begin()) * k);
}

void visit_kept(const PointCloud& cloud, const KeptNeighbourhoods& kept,
                const std::function<void(const Neighbourhood&)>& visit,
                const std::function<void(std::size_t)>& progress, std::span<const float> values) {
  if (!values.empty() && values.size() != cloud.size())
    throw Error("", "kept neighbourhoods",
                "has " + std::to_string(values.size()) + " values for " +
                    std::to_string(cloud.size()) + " points");
  const auto k = static_cast<std::size_t>(kept.k);
  struct Lists {
    std::vector<float> dx, dy, dz, values;
  };
  tbb::enumerable_thread_specific<Lists> lists([k] {
    return Lists{std::vector<float>(k), std::vector<float>(k), std::vector<float>(k),
                 std::vector<float>(k)};
  });
  parallel_for_chunks(kept.points.size(), 64, [&](std::size_t first, std::size_t end) {
    Lists& list = lists.local();
    for (std::size_t p = first; p < end; ++p) {
      const std::uint32_t point = kept.points[p];
      const std::uint32_t* indices = kept.neighbours.get() + p * k;
      // As for_each: the neighbour's coordinate minus the query's, in float.
      for (std::size_t j = 0; j < k; ++j) {
        list.dx[j] = cloud.x[indices[j]] - cloud.x[point];
        list.dy[j] = cloud.y[indices[j]] - cloud.y[point];
        list.dz[j] = cloud.z[indices[j]] - cloud.z[point];
        if (!values.empty()) list.values[j] = values[indices[j]];
      }
      Neighbourhood neighbourhood;
      neighbourhood.point = point;
      neighbourhood.size = kept.k;
      neighbourhood.dx = list.dx.data();
      neighbourhood.dy = list.dy.data();
      neighbourhood.dz = list.dz.data();
      neighbourhood.indices = indices;
      neighbourhood.values = values.empty() ? nullptr : list.values.data();
      visit(neighbourhood);
    }
    if (progress) progress(end - first);
  });
}

NeighbourhoodStats for_each_neighbourhood(const PointCloud& cloud,
                                          const NeighbourhoodParams& params,
                                          const std::function<void(const Neighbourhood&)>& visit,
                                          const std::function<void(std::size_t)>& progress) {
  return NeighbourhoodSearch(cloud, params).for_each(visit, progress);
}

}  // namespace glint::geometry
