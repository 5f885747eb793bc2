#include "edges/tiled_classify.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>

#include "core/distributed.h"
#include "core/error.h"
#include "core/log.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/timer.h"
#include "edges/classifier.h"
#include "edges/features.h"
#include "io/las.h"

namespace glint::edges {
namespace {

constexpr std::size_t kChunkPoints = 1 << 16;  // records per streamed read
constexpr std::uint64_t kMaxCountCells = 1ull << 23;
// Count grid, its pyramid, buffers and the executable itself, beside the tile.
constexpr std::uint64_t kFixedBytes = 400ull << 20;
constexpr std::size_t kResultBytes = 9;  // label, p_sharp, p_boundary

// One network's result of one point, as a tile file stores it.
void put_result(const Classification& result, std::size_t i, std::uint8_t* record) {
  record[0] = result.labels[i];
  std::memcpy(record + 1, &result.p_sharp[i], 4);
  std::memcpy(record + 5, &result.p_boundary[i], 4);
}

// A tile's point as stored in its bucket file.
struct TilePoint {
  float x, y, z;
  std::uint32_t flags;  // kCore, and a core point's gate-read mask << kGateReadsShift
};
constexpr std::uint32_t kCore = 1;  // the tile's own point (else a halo point)
constexpr int kGateReadsShift = 1;  // gate_tallies's read mask (edges/classifier.h)

// The rows [begin, end) of the input that rank `rank` of `ranks` streams in every pass.
std::pair<std::uint64_t, std::uint64_t> slice_of(std::uint64_t points, int rank, int ranks) {
  return {points * std::uint64_t(rank) / std::uint64_t(ranks),
          points * std::uint64_t(rank + 1) / std::uint64_t(ranks)};
}

// Streams records [begin, end) in chunks: visit(first_index, count, records).
template <class Visit>
void stream_records(const io::LasReader& reader, std::uint64_t begin, std::uint64_t end,
                    std::vector<std::uint8_t>& buffer, Visit&& visit) {
  const std::size_t length = reader.header().record_length;
  buffer.resize(kChunkPoints * length);
  for (std::uint64_t first = begin; first < end; first += kChunkPoints) {
    const auto count = static_cast<std::size_t>(std::min<std::uint64_t>(kChunkPoints, end - first));
    reader.read_records(first, count, buffer.data());
    visit(first, count, buffer.data());
  }
}

float relative(std::int32_t value, std::int64_t origin, double scale) {
  return static_cast<float>(double(std::int64_t(value) - origin) * scale);
}

// Counting grid over the bounding box in record units; cells are whole numbers of units.
struct CountGrid {
  std::int64_t low[3];
  std::int64_t width[3];  // cell size in record units
  std::int64_t dims[3];
  double cell_m[3];  // cell size in metres

  std::int64_t index(const std::int32_t xyz[3], int axis) const {
    return std::min<std::int64_t>((std::int64_t(xyz[axis]) - low[axis]) / width[axis],
                                  dims[axis] - 1);
  }
  std::size_t cell(std::int64_t ix, std::int64_t iy, std::int64_t iz) const {
    return static_cast<std::size_t>((ix * dims[1] + iy) * dims[2] + iz);
  }
};

CountGrid make_count_grid(const std::int64_t low[3], const std::int64_t high[3],
                          const double scale[3], std::uint64_t points) {
  // Eight cells per point at most: finer cells would mostly be empty (a surface fills few).
  const std::uint64_t max_cells = std::clamp<std::uint64_t>(8 * points, 4096, kMaxCountCells);
  CountGrid grid;
  double extent_m[3], volume = 1;
  for (int a = 0; a < 3; ++a) {
    grid.low[a] = low[a];
    extent_m[a] = double(high[a] - low[a] + 1) * scale[a];
    volume *= extent_m[a];
  }
  double cell = std::max(std::cbrt(volume / double(max_cells)), 1e-9);
  for (;;) {
    std::uint64_t cells = 1;
    for (int a = 0; a < 3; ++a) {
      grid.width[a] = std::max<std::int64_t>(1, std::int64_t(std::ceil(cell / scale[a])));
      grid.dims[a] = (high[a] - low[a]) / grid.width[a] + 1;
      grid.cell_m[a] = double(grid.width[a]) * scale[a];
      cells *= std::uint64_t(grid.dims[a]);
    }
    if (cells <= max_cells) break;
    cell *= 1.1;
  }
  return grid;
}

// The grid's counts summed over cells 2^l times larger per axis at level l (level 0: the grid).
struct CountPyramid {
  std::vector<std::vector<std::uint64_t>> levels;
  std::vector<std::array<std::int64_t, 3>> level_dims;
};

CountPyramid count_pyramid(const CountGrid& grid, const std::vector<std::uint64_t>& counts) {
  std::vector<std::vector<std::uint64_t>> levels{counts};
  std::vector<std::array<std::int64_t, 3>> level_dims{{grid.dims[0], grid.dims[1], grid.dims[2]}};
  while (level_dims.back()[0] > 1 || level_dims.back()[1] > 1 || level_dims.back()[2] > 1) {
    const auto& below = level_dims.back();
    const std::array<std::int64_t, 3> dims{(below[0] + 1) / 2, (below[1] + 1) / 2,
                                           (below[2] + 1) / 2};
    std::vector<std::uint64_t> up(std::size_t(dims[0] * dims[1] * dims[2]), 0);
    const std::vector<std::uint64_t>& source = levels.back();
    for (std::int64_t x = 0; x < below[0]; ++x) {
      for (std::int64_t y = 0; y < below[1]; ++y) {
        for (std::int64_t z = 0; z < below[2]; ++z) {
          up[std::size_t(((x / 2) * dims[1] + y / 2) * dims[2] + z / 2)] +=
              source[std::size_t((x * below[1] + y) * below[2] + z)];
        }
      }
    }
    levels.push_back(std::move(up));
    level_dims.push_back(dims);
  }
  return {std::move(levels), std::move(level_dims)};
}

// Per xy column of the count grid: the largest proven k-th neighbour distance bound (metres) of
// the cells in it, 0 for empty columns.
std::vector<double> column_halos(const CountGrid& grid, const CountPyramid& pyramid, int k) {
  const auto& levels = pyramid.levels;
  const auto& level_dims = pyramid.level_dims;
  const double diagonal =
      std::sqrt(grid.cell_m[0] * grid.cell_m[0] + grid.cell_m[1] * grid.cell_m[1] +
                grid.cell_m[2] * grid.cell_m[2]);
  std::vector<double> halos(std::size_t(grid.dims[0] * grid.dims[1]), 0.0);
  parallel_for(std::size_t(grid.dims[0]), [&](std::size_t ix) {
    for (std::int64_t iy = 0; iy < grid.dims[1]; ++iy) {
      double& halo = halos[std::size_t(std::int64_t(ix) * grid.dims[1] + iy)];
      for (std::int64_t iz = 0; iz < grid.dims[2]; ++iz) {
        if (levels[0][grid.cell(std::int64_t(ix), iy, iz)] == 0) continue;
        for (std::size_t level = 0; level < levels.size(); ++level) {
          const auto& dims = level_dims[level];
          const std::int64_t c[3] = {std::int64_t(ix) >> level, iy >> level, iz >> level};
          std::uint64_t total = 0;
          for (std::int64_t x = std::max<std::int64_t>(c[0] - 1, 0);
               x <= std::min(c[0] + 1, dims[0] - 1); ++x) {
            for (std::int64_t y = std::max<std::int64_t>(c[1] - 1, 0);
                 y <= std::min(c[1] + 1, dims[1] - 1); ++y) {
              for (std::int64_t z = std::max<std::int64_t>(c[2] - 1, 0);
                   z <= std::min(c[2] + 1, dims[2] - 1); ++z) {
                total += levels[level][std::size_t((x * dims[1] + y) * dims[2] + z)];
              }
            }
          }
          if (total >= std::uint64_t(k)) {
            // Every point of the block is within 2 cells per axis of any point in the centre
            // cell, so its k-th neighbour is closer than twice the cell diagonal.
            halo = std::max(halo, 2.0 * diagonal * double(1ull << level));
            break;
          }
        }
      }
    }
  });
  return halos;
}

// An area-weighted model also needs the spacings of a core point's neighbours, so the tile must
// hold their spacing neighbours too. A neighbour j lies within the column's halo h of the core
// point and j's spacing neighbour within the spacing bound of j's own column: h + the largest
// spacing bound of the columns within h. At most 3h, a bound that needs no window (j's spacing
// neighbour lies within 2h of j, since the core point's k nearest do), taken where the window
// of columns would be wide.
std::vector<double> area_weighted_halos(const CountGrid& grid, const std::vector<double>& halos,
                                        const std::vector<double>& spacing_halos) {
  constexpr std::int64_t kMaxWindow = 16;  // columns either side
  std::vector<double> reach(halos.size(), 0.0);
  parallel_for(std::size_t(grid.dims[0]), [&](std::size_t column_x) {
    const auto ix = std::int64_t(column_x);
    for (std::int64_t iy = 0; iy < grid.dims[1]; ++iy) {
      const std::size_t column = std::size_t(ix * grid.dims[1] + iy);
      const double h = halos[column];
      reach[column] = 3.0 * h;
      // A point within h of the column lies at most ceil(h / cell) columns away per axis.
      const auto wx = std::int64_t(std::ceil(h / grid.cell_m[0]));
      const auto wy = std::int64_t(std::ceil(h / grid.cell_m[1]));
      if (h == 0 || wx > kMaxWindow || wy > kMaxWindow) continue;
      double spacing = 0;
      for (std::int64_t x = std::max<std::int64_t>(0, ix - wx);
           x <= std::min(grid.dims[0] - 1, ix + wx); ++x)
        for (std::int64_t y = std::max<std::int64_t>(0, iy - wy);
             y <= std::min(grid.dims[1] - 1, iy + wy); ++y)
          spacing = std::max(spacing, spacing_halos[std::size_t(x * grid.dims[1] + y)]);
      reach[column] = std::min(reach[column], h + spacing);
    }
  });
  return reach;
}

// Square tiles of `side` count-grid columns, each with its own halo.
struct Tiling {
  std::int64_t side = 1;  // columns per tile edge
  std::int64_t tiles_x = 1, tiles_y = 1;
  std::vector<std::int64_t> halo_units_x, halo_units_y;  // per tile, record units
  std::vector<double> halo_m;
  std::int64_t max_halo_units_x = 0, max_halo_units_y = 0;

  std::size_t count() const { return std::size_t(tiles_x * tiles_y); }
};

// Sums of column counts over rectangles of columns, in O(1).
struct ColumnSums {
  std::int64_t nx, ny;
  std::vector<std::uint64_t> prefix;  // (nx + 1) x (ny + 1)
  ColumnSums(const CountGrid& grid, const std::vector<std::uint64_t>& counts)
      : nx(grid.dims[0]), ny(grid.dims[1]), prefix(std::size_t((nx + 1) * (ny + 1)), 0) {
    for (std::int64_t x = 0; x < nx; ++x) {
      for (std::int64_t y = 0; y < ny; ++y) {
        std::uint64_t column = 0;
        for (std::int64_t z = 0; z < grid.dims[2]; ++z) column += counts[grid.cell(x, y, z)];
        at(x + 1, y + 1) = column + at(x, y + 1) + at(x + 1, y) - at(x, y);
      }
    }
  }
  std::uint64_t& at(std::int64_t x, std::int64_t y) {
    return prefix[std::size_t(x * (ny + 1) + y)];
  }
  // Columns [x0, x1) x [y0, y1), clamped to the grid.
  std::uint64_t sum(std::int64_t x0, std::int64_t x1, std::int64_t y0, std::int64_t y1) {
    x0 = std::clamp<std::int64_t>(x0, 0, nx), x1 = std::clamp<std::int64_t>(x1, 0, nx);
    y0 = std::clamp<std::int64_t>(y0, 0, ny), y1 = std::clamp<std::int64_t>(y1, 0, ny);
    if (x0 >= x1 || y0 >= y1) return 0;
    return at(x1, y1) - at(x0, y1) - at(x1, y0) + at(x0, y0);
  }
};

// Tiling with `side` columns per tile; largest (core + halo) point count of a tile in
// `largest`.
Tiling make_tiling(const CountGrid& grid, const std::vector<double>& halos, ColumnSums& sums,
                   std::int64_t side, const double scale[3], std::uint64_t& largest) {
  Tiling tiling;
  tiling.side = side;
  tiling.tiles_x = (grid.dims[0] + side - 1) / side;
  tiling.tiles_y = (grid.dims[1] + side - 1) / side;
  largest = 0;
  for (std::int64_t tx = 0; tx < tiling.tiles_x; ++tx) {
    for (std::int64_t ty = 0; ty < tiling.tiles_y; ++ty) {
      double halo = 0;
      for (std::int64_t x = tx * side; x < std::min((tx + 1) * side, grid.dims[0]); ++x) {
        for (std::int64_t y = ty * side; y < std::min((ty + 1) * side, grid.dims[1]); ++y) {
          halo = std::max(halo, halos[std::size_t(x * grid.dims[1] + y)]);
        }
      }
      // Float positions and their rounding: a margin of 1e-4 and two record units.
      const std::int64_t units_x = std::int64_t(std::ceil(halo * (1 + 1e-4) / scale[0])) + 2;
      const std::int64_t units_y = std::int64_t(std::ceil(halo * (1 + 1e-4) / scale[1])) + 2;
      tiling.halo_m.push_back(halo);
      tiling.halo_units_x.push_back(units_x);
      tiling.halo_units_y.push_back(units_y);
      tiling.max_halo_units_x = std::max(tiling.max_halo_units_x, units_x);
      tiling.max_halo_units_y = std::max(tiling.max_halo_units_y, units_y);
      const std::int64_t columns_x = (units_x + grid.width[0] - 1) / grid.width[0];
      const std::int64_t columns_y = (units_y + grid.width[1] - 1) / grid.width[1];
      largest = std::max(largest, sums.sum(tx * side - columns_x, (tx + 1) * side + columns_x,
                                           ty * side - columns_y, (ty + 1) * side + columns_y));
    }
  }
  return tiling;
}

std::uint64_t default_memory_limit() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? std::uint64_t(pages) * std::uint64_t(page) / 4 * 3 : 8ull << 30;
}

// Removes the temporary tile folder when the job ends, however it ends (creating rank only).
struct TemporaryFolder {
  std::filesystem::path path;
  bool owner = false;
  ~TemporaryFolder() {
    std::error_code ignored;
    if (owner) std::filesystem::remove_all(path, ignored);
  }
};

std::FILE* open_file(const std::filesystem::path& path, const char* mode,
                     std::vector<char>& buffer) {
  std::FILE* file = std::fopen(path.c_str(), mode);
  if (!file) throw Error(path.string(), "", "cannot open a temporary tile file");
  std::setvbuf(file, buffer.data(), _IOFBF, buffer.size());
  return file;
}

struct FileCloser {
  void operator()(std::FILE* file) const {
    if (file) std::fclose(file);
  }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

void write_all(std::FILE* file, const void* data, std::size_t size, const std::string& what) {
  if (size > 0 && std::fwrite(data, 1, size, file) != size) {
    throw Error(what, "", "cannot write a temporary tile file (disk full?)");
  }
}

}  // namespace

std::uint64_t parse_memory_size(const std::string& text) {
  std::size_t used = 0;
  double value = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  const std::string unit = text.substr(used);
  double factor = 0;
  if (unit.empty() || unit == "B") factor = 1;
  if (unit == "K" || unit == "KB" || unit == "KiB") factor = 1024.0;
  if (unit == "M" || unit == "MB" || unit == "MiB") factor = 1024.0 * 1024;
  if (unit == "G" || unit == "GB" || unit == "GiB") factor = 1024.0 * 1024 * 1024;
  if (unit == "T" || unit == "TB" || unit == "TiB") factor = 1024.0 * 1024 * 1024 * 1024;
  if (used == 0 || factor == 0 || !(value > 0)) {
    throw Error("--memory-limit", text, "expected a size such as 2G, 512M or 1500000000");
  }
  return static_cast<std::uint64_t>(value * factor);
}

TiledClassifyStats classify_las(const std::string& input, const std::string& output,
                                const Model& model, const TiledClassifyParams& params) {
  const Stopwatch total_watch;
  Distributed& world = Distributed::world();
  const int rank = world.rank(), ranks = world.size();
  const io::LasReader reader(input);
  const io::LasHeader& header = reader.header();
  io::LasBoundedFields fields;
  const io::LasHeader out_header = io::las_header_with_bounded_fields(header, input, fields);
  std::int64_t origin[3];
  io::las_origin(header, origin);
  const std::uint64_t n = header.point_count;
  const std::size_t in_length = header.record_length, out_length = out_header.record_length;

  const std::vector<int> scales = params.scales.empty() ? model.config.scales : params.scales;
  const int k = scales.empty() ? 0 : scales.front();
  if (n < std::uint64_t(k)) {
    throw Error(input, "point data",
                fmt::format("has {} points; the largest scale needs at least {}", n, k));
  }
  const std::uint64_t limit =
      params.memory_limit_bytes ? params.memory_limit_bytes : default_memory_limit();
  if (limit <= kFixedBytes + std::uint64_t(k) * 64 * kTileBytesPerPoint) {
    throw Error("--memory-limit", fmt::format("{} MiB", limit >> 20),
                fmt::format("too small: at least {} MiB are needed",
                            (kFixedBytes + std::uint64_t(k) * 64 * kTileBytesPerPoint) >> 20));
  }
  std::uint64_t tile_limit = (limit - kFixedBytes) / kTileBytesPerPoint;
  if (params.tile_points > 0) tile_limit = std::min(tile_limit, params.tile_points);

  const std::vector<const Model*> gate_chain = model.gate_chain();
  TiledClassifyStats stats;
  stats.points = n;
  stats.points_per_tile_limit = tile_limit;

  // One job-wide tag names the temporary files of every rank.
  std::vector<std::int64_t> tag_value{rank == 0 ? std::int64_t(::getpid()) : 0};
  world.max(tag_value);
  const std::string tag = std::to_string(tag_value[0]);
  std::unique_ptr<io::LasWriter> writer;
  if (rank == 0) writer = std::make_unique<io::LasWriter>(output, tag, out_header, true);
  world.barrier();
  if (rank != 0) writer = std::make_unique<io::LasWriter>(output, tag, out_header, false);

  std::vector<std::uint8_t> buffer, out_buffer(kChunkPoints * out_length);
  // Copies a chunk of input records into output records with their results.
  auto write_chunk = [&](std::uint64_t first, std::size_t count, const std::uint8_t* records,
                         auto&& result_of) {
    for (std::size_t j = 0; j < count; ++j) {
      std::uint8_t* record = out_buffer.data() + j * out_length;
      std::memcpy(record, records + j * in_length, in_length);
      std::uint8_t label;
      float p_sharp, p_boundary;
      result_of(j, records + j * in_length, label, p_sharp, p_boundary);
      io::las_set_bounded_fields(record, fields, label, p_sharp, p_boundary);
      ++stats.labels[std::min<int>(label, 2)];
    }
    writer->write_records(first, count, out_buffer.data());
  };

  if (ranks == 1 && n <= tile_limit) {
    // The whole cloud at once.
    Stopwatch watch;
    PointCloud cloud;
    cloud.resize(n);
    stream_records(reader, 0, n, buffer,
                   [&](std::uint64_t first, std::size_t count, const std::uint8_t* records) {
                     for (std::size_t j = 0; j < count; ++j) {
                       std::int32_t xyz[3];
                       io::las_record_xyz(records + j * in_length, xyz);
                       cloud.x[first + j] = relative(xyz[0], origin[0], header.scale[0]);
                       cloud.y[first + j] = relative(xyz[1], origin[1], header.scale[1]);
                       cloud.z[first + j] = relative(xyz[2], origin[2], header.scale[2]);
                     }
                   });
    stats.read_s = watch.elapsed_s();
    watch.restart();
    Classification result;
    try {
      result = classify(cloud, model, scales);
    } catch (const Error& e) {
      throw Error(input, e.element(), e.reason());
    }
    stats.gates = result.gates;
    stats.classify_s = watch.elapsed_s();
    cloud = PointCloud();
    watch.restart();
    stream_records(reader, 0, n, buffer,
                   [&](std::uint64_t first, std::size_t count, const std::uint8_t* records) {
                     write_chunk(first, count, records,
                                 [&](std::size_t j, const std::uint8_t*, std::uint8_t& label,
                                     float& p_sharp, float& p_boundary) {
                                   label = result.labels[first + j];
                                   p_sharp = result.p_sharp[first + j];
                                   p_boundary = result.p_boundary[first + j];
                                 });
                   });
    writer->commit();
    stats.write_s = watch.elapsed_s();
    stats.rank_points = n;
    stats.total_s = total_watch.elapsed_s();
    return stats;
  }

  stats.tiled = true;
  const auto [slice_begin, slice_end] = slice_of(n, rank, ranks);
  Stopwatch watch;

  // Pass 1: bounding box in record units.
  std::vector<std::int64_t> low(3, std::numeric_limits<std::int64_t>::max());
  std::vector<std::int64_t> high(3, std::numeric_limits<std::int64_t>::min());
  stream_records(reader, slice_begin, slice_end, buffer,
                 [&](std::uint64_t, std::size_t count, const std::uint8_t* records) {
                   for (std::size_t j = 0; j < count; ++j) {
                     std::int32_t xyz[3];
                     io::las_record_xyz(records + j * in_length, xyz);
                     for (int a = 0; a < 3; ++a) {
                       low[a] = std::min<std::int64_t>(low[a], xyz[a]);
                       high[a] = std::max<std::int64_t>(high[a], xyz[a]);
                     }
                   }
                 });
  world.min(low);
  world.max(high);
  const CountGrid grid = make_count_grid(low.data(), high.data(), header.scale, n);

  // Pass 2: cell counts.
  std::vector<std::uint64_t> counts(std::size_t(grid.dims[0] * grid.dims[1] * grid.dims[2]), 0);
  stream_records(
      reader, slice_begin, slice_end, buffer,
      [&](std::uint64_t, std::size_t count, const std::uint8_t* records) {
        for (std::size_t j = 0; j < count; ++j) {
          std::int32_t xyz[3];
          io::las_record_xyz(records + j * in_length, xyz);
          ++counts[grid.cell(grid.index(xyz, 0), grid.index(xyz, 1), grid.index(xyz, 2))];
        }
      });
  world.sum(counts);
  // The pyramid (up to 8/7 of the counts) is freed before the tiles are read.
  const std::vector<double> halos = [&] {
    const CountPyramid pyramid = count_pyramid(grid, counts);
    std::vector<double> counting = column_halos(grid, pyramid, k);
    if (!model.config.area_weights) return counting;
    return area_weighted_halos(grid, counting,
                               column_halos(grid, pyramid, kAreaSpacingNeighbour + 1));
  }();

  // The largest tiles whose points, halo included, fit the limit.
  ColumnSums sums(grid, counts);
  counts = {};
  std::int64_t side = std::max(grid.dims[0], grid.dims[1]);
  std::uint64_t largest = 0;
  Tiling tiling = make_tiling(grid, halos, sums, side, header.scale, largest);
  // The tiling depends on the cloud and the limit only, never on the rank count, so any
  // number of ranks writes the same bytes.
  while (largest > tile_limit && side > 1) {
    side = std::max<std::int64_t>(1, std::min(side - 1, std::int64_t(double(side) * 0.85)));
    tiling = make_tiling(grid, halos, sums, side, header.scale, largest);
  }
  if (largest > tile_limit) {
    throw Error(input, "--memory-limit",
                fmt::format("a tile of one {:.3g} m column with its halo holds {} points, more "
                            "than the {} the limit allows; raise --memory-limit",
                            grid.cell_m[0], largest, tile_limit));
  }
  const std::size_t tile_count = tiling.count();
  const std::int64_t tile_units_x = tiling.side * grid.width[0];
  const std::int64_t tile_units_y = tiling.side * grid.width[1];
  stats.tile_side_m = double(tile_units_x) * header.scale[0];
  for (double h : tiling.halo_m) stats.halo_m_max = std::max(stats.halo_m_max, h);
  auto core_tile = [&](const std::int32_t xyz[3]) {
    return std::size_t(((std::int64_t(xyz[0]) - grid.low[0]) / tile_units_x) * tiling.tiles_y +
                       (std::int64_t(xyz[1]) - grid.low[1]) / tile_units_y);
  };

  // Pass 3: every point into the bucket of its core tile and of the tiles whose halo holds it.
  TemporaryFolder folder{std::filesystem::path(output + ".tiles-" + tag), rank == 0};
  if (rank == 0) std::filesystem::create_directories(folder.path);
  world.barrier();
  auto bucket_path = [&](std::size_t tile, int from_rank) {
    return folder.path / fmt::format("t{}-r{}.bin", tile, from_rank);
  };
  // tile_counts[t * ranks + r]: core points of tile t in rank r's slice; then the totals.
  std::vector<std::uint64_t> tile_counts(tile_count * std::size_t(ranks + 1), 0);
  {
    std::vector<std::vector<char>> file_buffers(tile_count);
    std::vector<File> buckets(tile_count);
    stream_records(
        reader, slice_begin, slice_end, buffer,
        [&](std::uint64_t first, std::size_t count, const std::uint8_t* records) {
          for (std::size_t j = 0; j < count; ++j) {
            std::int32_t xyz[3];
            io::las_record_xyz(records + j * in_length, xyz);
            // The points the gates read in the whole cloud.
            const std::uint32_t reads = gate_read_mask(gate_chain, first + j, n);
            const std::int64_t ux = std::int64_t(xyz[0]) - grid.low[0];
            const std::int64_t uy = std::int64_t(xyz[1]) - grid.low[1];
            const std::size_t own = core_tile(xyz);
            const TilePoint point{relative(xyz[0], origin[0], header.scale[0]),
                                  relative(xyz[1], origin[1], header.scale[1]),
                                  relative(xyz[2], origin[2], header.scale[2]), 0};
            const std::int64_t tx0 =
                std::max<std::int64_t>(0, (ux - tiling.max_halo_units_x) / tile_units_x);
            const std::int64_t tx1 =
                std::min(tiling.tiles_x - 1, (ux + tiling.max_halo_units_x) / tile_units_x);
            const std::int64_t ty0 =
                std::max<std::int64_t>(0, (uy - tiling.max_halo_units_y) / tile_units_y);
            const std::int64_t ty1 =
                std::min(tiling.tiles_y - 1, (uy + tiling.max_halo_units_y) / tile_units_y);
            for (std::int64_t tx = tx0; tx <= tx1; ++tx) {
              for (std::int64_t ty = ty0; ty <= ty1; ++ty) {
                const std::size_t t = std::size_t(tx * tiling.tiles_y + ty);
                const std::int64_t hx = tiling.halo_units_x[t], hy = tiling.halo_units_y[t];
                if (t != own &&
                    (ux < tx * tile_units_x - hx || ux >= (tx + 1) * tile_units_x + hx ||
                     uy < ty * tile_units_y - hy || uy >= (ty + 1) * tile_units_y + hy)) {
                  continue;
                }
                if (!buckets[t]) {
                  file_buffers[t].resize(1 << 16);
                  buckets[t].reset(open_file(bucket_path(t, rank), "wb", file_buffers[t]));
                }
                TilePoint stored = point;
                stored.flags = t == own ? kCore | reads << kGateReadsShift : 0;
                write_all(buckets[t].get(), &stored, sizeof stored, bucket_path(t, rank));
                if (t == own) ++tile_counts[t * std::size_t(ranks) + std::size_t(rank)];
                ++tile_counts[tile_count * std::size_t(ranks) + t];
              }
            }
          }
        });
    for (std::size_t t = 0; t < tile_count; ++t) {
      if (buckets[t] && std::fflush(buckets[t].get()) != 0) {
        throw Error(bucket_path(t, rank).string(), "", "cannot write a temporary tile file");
      }
    }
  }
  world.sum(tile_counts);
  stats.read_s = watch.elapsed_s();
  auto core_count = [&](std::size_t t, int r) {
    return tile_counts[t * std::size_t(ranks) + std::size_t(r)];
  };
  std::vector<std::uint64_t> tile_total(tile_count), tile_core(tile_count, 0);
  for (std::size_t t = 0; t < tile_count; ++t) {
    tile_total[t] = tile_counts[tile_count * std::size_t(ranks) + t];
    for (int r = 0; r < ranks; ++r) tile_core[t] += core_count(t, r);
    if (tile_core[t] > 0) ++stats.tiles;
    stats.halo_points += tile_total[t] - tile_core[t];
  }

  // Tiles to ranks: largest first, each to the least loaded rank.
  std::vector<std::size_t> order(tile_count);
  for (std::size_t t = 0; t < tile_count; ++t) order[t] = t;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return tile_total[a] > tile_total[b]; });
  std::vector<std::uint64_t> load(std::size_t(ranks), 0);
  std::vector<std::size_t> mine;
  for (const std::size_t t : order) {
    if (tile_core[t] == 0) continue;
    const auto least = std::size_t(std::min_element(load.begin(), load.end()) - load.begin());
    load[least] += tile_total[t];
    if (int(least) == rank) mine.push_back(t);
  }
  std::sort(mine.begin(), mine.end());
  log().info(
      "{} points in {} tiles of {:.1f} m with halos up to {:.2f} m ({:.1f} % halo "
      "points); this rank: {} tiles",
      n, stats.tiles, stats.tile_side_m, stats.halo_m_max,
      100.0 * double(stats.halo_points) / double(n), mine.size());

  std::vector<char> file_buffer(1 << 20);
  // A tile's core and halo points from every rank's bucket, with their flags.
  auto load_tile = [&](std::size_t t, PointCloud& cloud, std::vector<std::uint8_t>& flags) {
    cloud = PointCloud();
    cloud.reserve(tile_total[t]);
    flags.clear();
    flags.reserve(tile_total[t]);
    for (int r = 0; r < ranks; ++r) {
      const std::filesystem::path path = bucket_path(t, r);
      if (!std::filesystem::exists(path)) continue;
      File file(open_file(path, "rb", file_buffer));
      TilePoint point;
      while (std::fread(&point, sizeof point, 1, file.get()) == 1) {
        cloud.push_back(point.x, point.y, point.z);
        flags.push_back(static_cast<std::uint8_t>(point.flags));
      }
    }
    if (cloud.size() != tile_total[t]) {
      throw Error(
          bucket_path(t, 0).string(), "",
          fmt::format("tile {} holds {} points, {} were written", t, cloud.size(), tile_total[t]));
    }
  };
  std::uint64_t rank_points = 0;
  for (const std::size_t t : mine) rank_points += tile_core[t];
  stats.rank_points = rank_points;
  stats.rank_tiles = mine.size();
  PointCloud cloud;
  std::vector<std::uint8_t> flags;
  const bool was_quiet = is_quiet();

  // The gates choose the file's network before any tile is classified, each from the core
  // points it reads (the same points as in the whole cloud).
  watch.restart();
  const Model* network = &model;
  if (model.gated()) {
    std::vector<GateTally> tallies;
    for (const Model* gated : gate_chain) tallies.push_back(gated->new_tally());
    ProgressBar progress("gate", rank_points);
    for (const std::size_t t : mine) {
      load_tile(t, cloud, flags);
      std::vector<std::uint8_t> reads(flags.size());
      for (std::size_t i = 0; i < flags.size(); ++i)
        reads[i] = (flags[i] & kCore) ? std::uint8_t(flags[i] >> kGateReadsShift) : 0;
      try {
        const std::vector<GateTally> tile_tallies = gate_tallies(cloud, model, reads, scales);
        for (std::size_t g = 0; g < tallies.size(); ++g) tallies[g].merge(tile_tallies[g]);
      } catch (const Error& e) {
        throw Error(input, e.element(), fmt::format("tile {}: {}", t, e.reason()));
      }
      progress.advance(tile_core[t]);
    }
    progress.finish();
    for (std::size_t g = 0; g < tallies.size(); ++g) {
      world.sum(tallies[g].counts());
      stats.gates.push_back(tallies[g].decision());
      if (!stats.gates.back().gate_network_answered) break;
    }
    network = &model.answering_network(stats.gates);
  }

  // Per tile: classify core and halo together, keep the core's results in input order.
  {
    ProgressBar progress("classify", rank_points);
    for (const std::size_t t : mine) {
      load_tile(t, cloud, flags);
      set_quiet(true);  // one bar over all tiles, not one per tile
      Classification result;
      try {
        result = classify_ungated(cloud, *network, scales);
      } catch (const Error& e) {
        set_quiet(was_quiet);
        throw Error(input, e.element(), fmt::format("tile {}: {}", t, e.reason()));
      }
      set_quiet(was_quiet);
      const std::filesystem::path result_path = folder.path / fmt::format("t{}.res", t);
      File results(open_file(result_path, "wb", file_buffer));
      for (std::size_t i = 0; i < cloud.size(); ++i) {
        if (!(flags[i] & kCore)) continue;
        std::uint8_t record[kResultBytes];
        put_result(result, i, record);
        write_all(results.get(), record, kResultBytes, result_path.string());
      }
      if (std::fflush(results.get()) != 0) {
        throw Error(result_path.string(), "", "cannot write a temporary tile file");
      }
      std::error_code ignored;
      for (int r = 0; r < ranks; ++r) std::filesystem::remove(bucket_path(t, r), ignored);
      progress.advance(tile_core[t]);
    }
    progress.finish();
  }
  cloud = PointCloud();
  stats.classify_s = watch.elapsed_s();
  world.barrier();

  // Pass 4: the output, in input order; each point takes the next result of its core tile.
  watch.restart();
  {
    std::vector<std::vector<char>> file_buffers(tile_count);
    std::vector<File> results(tile_count);
    for (std::size_t t = 0; t < tile_count; ++t) {
      std::uint64_t before = 0;
      for (int r = 0; r < rank; ++r) before += core_count(t, r);
      if (core_count(t, rank) == 0) continue;
      file_buffers[t].resize(1 << 15);
      const std::filesystem::path path = folder.path / fmt::format("t{}.res", t);
      results[t].reset(open_file(path, "rb", file_buffers[t]));
      if (::fseeko(results[t].get(), off_t(before * kResultBytes), SEEK_SET) != 0) {
        throw Error(path.string(), "", "cannot seek in a temporary tile file");
      }
    }
    stream_records(reader, slice_begin, slice_end, buffer,
                   [&](std::uint64_t first, std::size_t count, const std::uint8_t* records) {
                     write_chunk(first, count, records,
                                 [&](std::size_t, const std::uint8_t* record, std::uint8_t& label,
                                     float& p_sharp, float& p_boundary) {
                                   std::int32_t xyz[3];
                                   io::las_record_xyz(record, xyz);
                                   const std::size_t t = core_tile(xyz);
                                   std::uint8_t bytes[kResultBytes];
                                   if (!results[t] ||
                                       std::fread(bytes, kResultBytes, 1, results[t].get()) != 1) {
                                     throw Error(folder.path.string(), "",
                                                 fmt::format("tile {} has too few results", t));
                                   }
                                   label = bytes[0];
                                   std::memcpy(&p_sharp, bytes + 1, 4);
                                   std::memcpy(&p_boundary, bytes + 5, 4);
                                 });
                   });
  }
  stats.write_s = watch.elapsed_s();
  // Label counts of the whole output.
  std::vector<std::uint64_t> labels(stats.labels, stats.labels + 3);
  world.sum(labels);
  std::copy(labels.begin(), labels.end(), stats.labels);
  world.barrier();
  if (rank == 0) writer->commit();
  world.barrier();
  stats.total_s = total_watch.elapsed_s();
  return stats;
}

}  // namespace glint::edges
