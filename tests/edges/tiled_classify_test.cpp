// LAS classification in tiles with halos and over MPI ranks: byte-identical to classifying the
// whole cloud at once, independent of the file's georeferencing offset, and no output at all
// when the input is bad.
#include "edges/tiled_classify.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include "core/build_info.h"
#include "edges/synth.h"
#include "io/las.h"
#include "support/cli_fixture.h"
#include "support/error_of.h"

namespace glint::edges {
namespace {

namespace fs = std::filesystem;

// The shipped 3-class model's own network, its sampling gate left out: tests add gates of
// their own.
const Model& bounded_model() {
  static const Model model = [] {
    Model shipped = Model::load(std::string(GLINT_TEST_DATA_DIR) + "/../../models/bounded-3c.json");
    shipped.gate_network = nullptr;
    return shipped;
  }();
  return model;
}

std::vector<std::uint8_t> file_bytes(const std::string& path) {
  std::ifstream stream(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(stream), {}};
}

// Three synthetic shapes 10 m apart on a ground strip, quantised to 0.1 mm, LAS 1.2 format 1;
// `noise` m of Gaussian noise on every coordinate.
void write_scene(const std::string& path, const double offset[3], double noise = 0) {
  SynthParams synth;
  synth.seed = 4;
  synth.min_points = 2500;
  synth.max_points = 3000;
  synth.noise_levels = {0.0};
  synth.outlier_probability = 0;
  synth.shapes = {SynthShape::box, SynthShape::open_box, SynthShape::cylinder};
  std::vector<std::array<double, 3>> points;
  for (int s = 0; s < 3; ++s) {
    const PointCloud cloud = synthesize_cloud(synth, std::uint64_t(s)).cloud;
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const float p[3] = {cloud.x[i], cloud.y[i], cloud.z[i]};
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
    }
    const double size = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]});
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      points.push_back({10.0 * s + 2.0 * (cloud.x[i] - lo[0]) / size,
                        2.0 * (cloud.y[i] - lo[1]) / size, 2.0 * (cloud.z[i] - lo[2]) / size});
    }
  }
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 6000; ++i) points.push_back({-1 + 32 * u(rng), -1 + 4 * u(rng), -0.2});

  std::normal_distribution<double> displacement(0.0, noise);
  if (noise > 0)
    for (auto& point : points)
      for (double& coordinate : point) coordinate += displacement(rng);

  const double scale[3] = {1e-4, 1e-4, 1e-4};
  std::vector<std::uint8_t> records(points.size() * 28, 0);
  std::int32_t lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::int32_t xyz[3];
    for (int a = 0; a < 3; ++a) {
      xyz[a] = std::int32_t(std::llround(points[i][a] / scale[a]));
      lo[a] = std::min(lo[a], xyz[a]), hi[a] = std::max(hi[a], xyz[a]);
    }
    std::memcpy(records.data() + i * 28, xyz, 12);
    records[i * 28 + 15] = 6;  // Classification: building, must survive
  }
  double min[3], max[3];
  for (int a = 0; a < 3; ++a) {
    min[a] = lo[a] * scale[a] + offset[a];
    max[a] = hi[a] * scale[a] + offset[a];
  }
  io::LasHeader header = io::make_las_header(2, 1, 0, points.size(), scale, offset, min, max);
  io::LasWriter writer(path, "scene", header, true);
  writer.write_records(0, points.size(), records.data());
  writer.commit();
}

// How two outputs of the same input differ: point for point labels, probabilities, and every
// other byte (header, VLRs, the input's own fields).
struct OutputDifference {
  std::size_t labels = 0;
  std::size_t probabilities = 0;
  float largest_probability = 0;
  bool other_bytes_equal = true;
};

OutputDifference compare_outputs(const std::string& a_path, const std::string& b_path) {
  const std::vector<std::uint8_t> a = file_bytes(a_path), b = file_bytes(b_path);
  OutputDifference difference;
  if (a.size() != b.size()) return {~std::size_t(0), 0, 0, false};
  const io::LasReader reader(a_path);
  const io::LasHeader& header = reader.header();
  const io::LasExtraField* label = header.find_extra("bounded_label");
  const std::size_t begin = header.offset_to_points, length = header.record_length;
  difference.other_bytes_equal =
      std::equal(a.begin(), a.begin() + std::ptrdiff_t(begin), b.begin());
  for (std::size_t i = 0; i < header.point_count; ++i) {
    const std::uint8_t* x = a.data() + begin + i * length;
    const std::uint8_t* y = b.data() + begin + i * length;
    difference.other_bytes_equal &= std::memcmp(x, y, label->offset) == 0;
    difference.labels += x[label->offset] != y[label->offset];
    for (std::size_t p : {label->offset + 1, label->offset + 5}) {
      float u, v;
      std::memcpy(&u, x + p, 4);
      std::memcpy(&v, y + p, 4);
      difference.probabilities += u != v;
      difference.largest_probability = std::max(difference.largest_probability, std::abs(u - v));
    }
  }
  return difference;
}

class TiledClassify : public CliTest {};

// Labels point for point; probabilities too except where a neighbour search orders points at
// exactly equal distance differently in a tile (decisions.md), which quantised coordinates make
// possible: then by little, and for few points.
TEST_F(TiledClassify, TilesGiveTheWholeCloudsLabelsPointForPoint) {
  const double origin[3] = {0, 0, 0};
  write_scene(path("scene.las"), origin);
  const TiledClassifyStats whole =
      classify_las(path("scene.las"), path("whole.las"), bounded_model());
  EXPECT_FALSE(whole.tiled);
  TiledClassifyParams params;
  params.tile_points = 9000;
  const TiledClassifyStats tiled =
      classify_las(path("scene.las"), path("tiled.las"), bounded_model(), params);
  EXPECT_TRUE(tiled.tiled);
  EXPECT_GE(tiled.tiles, 2u);
  EXPECT_GT(tiled.halo_points, 0u);
  EXPECT_GT(tiled.labels[1] + tiled.labels[2], 0u);  // the shapes have edges
  const OutputDifference difference = compare_outputs(path("whole.las"), path("tiled.las"));
  EXPECT_TRUE(difference.other_bytes_equal);
  EXPECT_EQ(difference.labels, 0u);
  EXPECT_LE(difference.probabilities, whole.points / 100);
  EXPECT_LT(difference.largest_probability, 0.05f);
  // Nothing of the tiles is left behind.
  for (const auto& entry : fs::directory_iterator(folder_)) {
    EXPECT_EQ(entry.path().string().find(".tiles-"), std::string::npos) << entry.path();
  }

  const PointCloud out = io::read_las(path("tiled.las"));
  EXPECT_EQ((*out.get<std::uint8_t>("classification"))[0], 6);  // never overwritten
  EXPECT_EQ(out.get<std::uint8_t>("scalar_label")->size(), whole.points);
}

// With area weights the neighbours' own spacings count too: the tiles' wider halos still give
// every point the whole cloud's label.
TEST_F(TiledClassify, AreaWeightedTilesGiveTheWholeCloudsLabels) {
  const double origin[3] = {0, 0, 0};
  write_scene(path("scene.las"), origin);
  Model model = bounded_model();
  model.config.area_weights = true;
  classify_las(path("scene.las"), path("whole.las"), model);
  TiledClassifyParams params;
  params.tile_points = 13500;  // of 14,063: the wider halos need large tiles
  const TiledClassifyStats tiled =
      classify_las(path("scene.las"), path("tiled.las"), model, params);
  EXPECT_TRUE(tiled.tiled);
  EXPECT_GE(tiled.tiles, 2u);
  const OutputDifference difference = compare_outputs(path("whole.las"), path("tiled.las"));
  EXPECT_TRUE(difference.other_bytes_equal);
  EXPECT_EQ(difference.labels, 0u);
  EXPECT_LT(difference.largest_probability, 0.05f);
  // The halos reach further than the counting model's, at most three times as far (the bounds
  // of area_weighted_halos).
  const TiledClassifyStats counted =
      classify_las(path("scene.las"), path("counted.las"), bounded_model(), params);
  EXPECT_GT(tiled.halo_points, counted.halo_points);
  EXPECT_GT(tiled.halo_m_max, counted.halo_m_max);
  EXPECT_LE(tiled.halo_m_max, 3.0 * counted.halo_m_max * (1 + 1e-9));
}

// A noise-gated model chooses one network for the whole file: in tiles the same one, from the
// quiet points of every tile's core it reads, as for the cloud at once.
TEST_F(TiledClassify, AGatedModelChoosesOneNetworkForTheWholeFileInTilesToo) {
  const double origin[3] = {0, 0, 0};
  write_scene(path("scene.las"), origin);
  Model low_noise = bounded_model();
  low_noise.layers.back().bias[2] += 4.0f;  // a network that calls far more points boundary
  const Model gated = bounded_model().with_gate(GateKind::noise, low_noise, 0.1f);
  const TiledClassifyStats whole = classify_las(path("scene.las"), path("whole.las"), gated);
  EXPECT_TRUE(whole.gates.at(0).gate_network_answered);  // clean shapes on a flat ground
  classify_las(path("scene.las"), path("alone.las"), low_noise);
  const OutputDifference as_alone = compare_outputs(path("whole.las"), path("alone.las"));
  EXPECT_EQ(as_alone.labels, 0u);
  EXPECT_EQ(as_alone.probabilities, 0u);

  TiledClassifyParams params;
  params.tile_points = 9000;
  const TiledClassifyStats tiled =
      classify_las(path("scene.las"), path("tiled.las"), gated, params);
  EXPECT_TRUE(tiled.tiled);
  EXPECT_TRUE(tiled.gates.at(0).gate_network_answered);
  EXPECT_NEAR(tiled.gates.at(0).statistic, whole.gates.at(0).statistic, 0.01);
  const OutputDifference difference = compare_outputs(path("whole.las"), path("tiled.las"));
  EXPECT_TRUE(difference.other_bytes_equal);
  EXPECT_EQ(difference.labels, 0u);

  // A noisy scene: the noisy network, the ungated model's output.
  write_scene(path("noisy-scene.las"), origin, 0.1);
  const TiledClassifyStats noisy =
      classify_las(path("noisy-scene.las"), path("noisy.las"), gated, params);
  EXPECT_FALSE(noisy.gates.at(0).gate_network_answered);
  classify_las(path("noisy-scene.las"), path("ungated.las"), bounded_model(), params);
  EXPECT_EQ(compare_outputs(path("noisy.las"), path("ungated.las")).labels, 0u);
  EXPECT_EQ(compare_outputs(path("noisy.las"), path("ungated.las")).probabilities, 0u);
}

// A sampling gate's spread comes from every tile's core points: the whole file's, in tiles too;
// so do the decisions of a chain of gates.
TEST_F(TiledClassify, GatesReadTheWholeFileInTiles) {
  const double origin[3] = {0, 0, 0};
  write_scene(path("scene.las"), origin);
  Model mesh_vertex = bounded_model();
  mesh_vertex.layers.back().bias[2] += 4.0f;
  // Thresholds just below and far above the scene's spread: each network answers once.
  const Model probe = bounded_model().with_gate(GateKind::sampling, mesh_vertex, 100.0f);
  const TiledClassifyStats spread = classify_las(path("scene.las"), path("probe.las"), probe);
  ASSERT_GT(spread.gates.at(0).statistic, 0.1);
  // The scene at once and in tiles: the same network and labels.
  auto whole_and_tiled = [&](const Model& gated) {
    const TiledClassifyStats whole = classify_las(path("scene.las"), path("whole.las"), gated);
    TiledClassifyParams params;
    params.tile_points = 9000;
    const TiledClassifyStats tiled =
        classify_las(path("scene.las"), path("tiled.las"), gated, params);
    EXPECT_TRUE(tiled.tiled);
    EXPECT_EQ(network_name(tiled.gates), network_name(whole.gates));
    EXPECT_EQ(compare_outputs(path("whole.las"), path("tiled.las")).labels, 0u);
    return std::pair{whole, tiled};
  };
  for (const float threshold : {float(spread.gates.at(0).statistic) - 0.05f, 100.0f}) {
    const auto [whole, tiled] =
        whole_and_tiled(bounded_model().with_gate(GateKind::sampling, mesh_vertex, threshold));
    EXPECT_EQ(whole.gates.at(0).gate_network_answered, threshold < 100.0f);
    EXPECT_NEAR(tiled.gates.at(0).statistic, whole.gates.at(0).statistic,
                1.0 / GateTally::kBinsPerUnit);
  }

  // A chain: the sampling gate passes the file on to a noise gate, in tiles as at once.
  const auto [whole, tiled] = whole_and_tiled(bounded_model().with_gate(
      GateKind::sampling, bounded_model().with_gate(GateKind::noise, mesh_vertex, 0.1f),
      float(spread.gates.at(0).statistic) - 0.05f));
  EXPECT_EQ(network_name(whole.gates), "mesh-vertex/low-noise");  // clean shapes, flat ground
  EXPECT_NEAR(tiled.gates.at(1).statistic, whole.gates.at(1).statistic, 0.01);
  classify_las(path("scene.las"), path("alone.las"), mesh_vertex);
  EXPECT_EQ(compare_outputs(path("whole.las"), path("alone.las")).probabilities, 0u);
}

TEST_F(TiledClassify, FarFromTheOriginClassifiesExactlyAsAtTheOrigin) {
  const double origin[3] = {0, 0, 0}, far[3] = {1.0e6, 5.0e6, 250.0};
  write_scene(path("near.las"), origin);
  write_scene(path("far.las"), far);
  classify_las(path("near.las"), path("near_out.las"), bounded_model());
  classify_las(path("far.las"), path("far_out.las"), bounded_model());
  const io::LasReader near_out(path("near_out.las")), far_out(path("far_out.las"));
  EXPECT_EQ(far_out.header().offset[0], 1.0e6);  // scale and offset kept
  EXPECT_EQ(far_out.header().scale[0], 1e-4);
  const std::size_t n = near_out.header().point_count;
  const std::size_t length = near_out.header().record_length;
  std::vector<std::uint8_t> a(n * length), b(n * length);
  near_out.read_records(0, n, a.data());
  far_out.read_records(0, n, b.data());
  EXPECT_EQ(a, b);  // raw coordinates and results alike
}

TEST_F(TiledClassify, BadInputLeavesNoOutput) {
  const double origin[3] = {0, 0, 0};
  write_scene(path("scene.las"), origin);
  std::vector<std::uint8_t> bytes = file_bytes(path("scene.las"));
  bytes.resize(bytes.size() - 100);
  std::ofstream(path("cut.las"), std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  const Error e = glint::test::error_of(
      [&] { classify_las(path("cut.las"), path("out.las"), bounded_model()); });
  EXPECT_EQ(e.element(), "point data");
  const CommandResult cli = glint("edges classify " + path("cut.las") + " -o " + path("out.las"));
  EXPECT_EQ(cli.exit_code, 1);
  EXPECT_NE(cli.output.find("truncated"), std::string::npos) << cli.output;
  for (const auto& entry : fs::directory_iterator(folder_)) {
    EXPECT_EQ(entry.path().filename().string().rfind("out.las", 0), std::string::npos)
        << entry.path();
  }
}

TEST(MemorySize, ParsesUnits) {
  EXPECT_EQ(parse_memory_size("2G"), 2ull << 30);
  EXPECT_EQ(parse_memory_size("512M"), 512ull << 20);
  EXPECT_EQ(parse_memory_size("1.5G"), 3ull << 29);
  EXPECT_EQ(parse_memory_size("1000"), 1000u);
  EXPECT_THROW(parse_memory_size("lots"), Error);
  EXPECT_THROW(parse_memory_size("2X"), Error);
}

// mpirun with three ranks: one output, byte-identical to the single process's with the same
// tiles (the tiling does not depend on the rank count). Skipped where
// mpirun is missing or glint was built without MPI; then a launch of several copies must be
// refused instead.
TEST_F(TiledClassify, MpiRanksWriteTheSingleProcessOutput) {
  if (std::system("command -v mpirun > /dev/null 2>&1") != 0) GTEST_SKIP() << "no mpirun";
  const double origin[3] = {0, 0, 0};
  write_scene(path("scene.las"), origin);
  TiledClassifyParams params;
  params.tile_points = 9000;
  classify_las(path("scene.las"), path("single.las"), bounded_model(), params);
  const std::string mpirun =
      "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "
      "OMPI_MCA_rmaps_base_oversubscribe=1 "
      "mpirun --oversubscribe -n 3 ";
  const std::string log = path("mpirun.log");
  const int status = std::system((mpirun + GLINT_BINARY + " --quiet --threads 1 edges classify " +
                                  path("scene.las") + " -o " + path("mpi.las") +
                                  " --tile-points 9000 > " + log + " 2>&1")
                                     .c_str());
  std::ifstream stream(log);
  const std::string output{std::istreambuf_iterator<char>(stream), {}};
  if (!build_info().mpi) {
    EXPECT_NE(WEXITSTATUS(status), 0);
    EXPECT_NE(output.find("built without MPI"), std::string::npos) << output;
    EXPECT_FALSE(fs::exists(path("mpi.las")));
    GTEST_SKIP() << "glint built without MPI: the launch was refused, as it must be";
  }
  ASSERT_EQ(WEXITSTATUS(status), 0) << output;
  EXPECT_NE(output.find("rank 2/3"), std::string::npos) << output;
  EXPECT_EQ(file_bytes(path("single.las")), file_bytes(path("mpi.las")));
}

}  // namespace
}  // namespace glint::edges
