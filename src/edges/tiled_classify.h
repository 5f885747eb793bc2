#pragma once
// BoundED on LAS surveys of any size: out-of-core spatial tiles with halos, spread over the
// ranks of an MPI job, output identical to classifying the whole cloud at once.
//
// The cloud is cut into square xy tiles (columns over all z). A tile is classified together
// with a halo of neighbouring points at least as wide as the largest-scale (k-th) neighbour
// distance of any of its points, so each of its points sees exactly the neighbours it has in
// the whole cloud; the halo's own labels are discarded. The halo width is measured, not
// guessed: a counting grid over the whole cloud gives every cell a proven bound on the k-th
// neighbour distance of its points (a 3x3x3 block of cells, at the finest level of a cell
// pyramid where the block holds at least k points, contains k points closer than twice the
// cell diagonal), and a tile's halo is the largest bound among its cells.
//
// Passes over the input, each streaming fixed-size chunks: bounding box; cell counts; bucketing
// of every point into the tiles whose core or halo holds it (temporary files next to the
// output); per tile: classification; the output, written in input order with each point's
// results from its core tile. A gated model's gates first tally the cores of every tile and
// choose one network for the whole file, as the whole-cloud run does, before any tile is
// classified. With R ranks each reads 1/R of the input in every pass and
// classifies its share of the tiles; all write their part of one output file.
//
// Positions become float relative to the file's integer origin (io/las.h) in every tile and in
// the whole-cloud run alike, so both compute from the same floats.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "edges/model.h"

namespace glint::edges {

struct TiledClassifyParams {
  std::vector<int> scales;               // neighbourhood sizes; empty = the model's
  std::uint64_t memory_limit_bytes = 0;  // 0 = three quarters of the machine's memory
  // Points per tile (core + halo) at most; 0 = as many as the memory limit allows. The whole
  // cloud is classified at once (no tiles) when it fits and only one process runs.
  std::uint64_t tile_points = 0;
};

struct TiledClassifyStats {
  std::uint64_t points = 0;
  std::uint64_t labels[3] = {0, 0, 0};  // non-edge, sharp, boundary
  // A gated model: what its gates decided for the whole file (Classification::gates).
  std::vector<GateDecision> gates;
  bool tiled = false;
  std::size_t tiles = 0;          // non-empty tiles
  std::uint64_t halo_points = 0;  // summed over tiles (points read twice or more)
  double halo_m_max = 0;          // widest halo
  double tile_side_m = 0;
  std::uint64_t points_per_tile_limit = 0;
  std::uint64_t rank_points = 0;  // core points this rank classified
  std::size_t rank_tiles = 0;
  double read_s = 0;      // bounding box, counts, bucketing
  double classify_s = 0;  // features and network, this rank
  double write_s = 0;     // output pass, this rank
  double total_s = 0;
};

// Classifies every point of the LAS file `input` and writes `output`: the input with
// bounded_label, p_sharp and p_boundary Extra Bytes (io/las.h). Collective over
// Distributed::world(): every rank calls it with the same arguments. Throws glint::Error for
// bad input, a memory limit too small for one tile of the cloud, or I/O failures; the output
// is then not created.
TiledClassifyStats classify_las(const std::string& input, const std::string& output,
                                const Model& model, const TiledClassifyParams& params = {});

// Bytes per point a tile may need while it is classified (positions, neighbour grid, network
// outputs), measured with some margin. Conservative: it counts a feature matrix at four scales
// (192 bytes per point) that classify() does not store.
inline constexpr std::uint64_t kTileBytesPerPoint = 320;

// Parses a memory size such as "2G", "512M", "1.5G" or "1000000" (bytes); throws glint::Error.
std::uint64_t parse_memory_size(const std::string& text);

}  // namespace glint::edges
