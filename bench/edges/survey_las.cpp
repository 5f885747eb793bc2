// survey_las: a synthetic georeferenced LAS survey for the out-of-core and MPI benchmarks of
// `glint edges classify`. An undulating ground over a square area (UTM-like offsets) with
// glint's procedural BoundED shapes (edges/synth.h: boxes, stairs, cylinders, open sheets ...)
// scaled to building size and set on it at the ground's point density; LAS 1.4, point
// format 6, millimetre quantisation, streamed in blocks (never the whole cloud in memory).
//
//   survey_las --points 100000000 --side 1000 --seed 1 -o survey.las
#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include "core/parallel.h"
#include "edges/synth.h"
#include "io/las.h"

namespace {

constexpr std::size_t kBlockPoints = 1 << 20;
constexpr double kScale = 0.001;
constexpr double kOffset[3] = {500000.0, 5500000.0, 0.0};
constexpr double kPartShare = 0.35;                // share of points on the shapes
constexpr std::uint64_t kMeanShapePoints = 78000;  // mean of log-uniform 20k..200k

double ground_height(double x, double y) {
  return 3.0 * std::sin(x / 90.0) + 2.0 * std::cos(y / 70.0) + 0.5 * std::sin((x + y) / 23.0);
}

struct Record {
  std::int32_t xyz[3];
  std::uint16_t intensity;
  std::uint8_t classification;
};

void encode(const Record& r, std::uint64_t index, std::uint8_t* out) {
  std::memset(out, 0, 30);
  std::memcpy(out, r.xyz, 12);
  std::memcpy(out + 12, &r.intensity, 2);
  out[14] = 0x11;  // return 1 of 1
  out[16] = r.classification;
  const double gps_time = double(index) * 1e-5;
  std::memcpy(out + 22, &gps_time, 8);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Writes a synthetic georeferenced LAS survey (ground + BoundED shapes)."};
  std::uint64_t points = 10000000;
  double side = 0;
  std::uint64_t seed = 1;
  std::string output;
  app.add_option("--points", points, "Total points")->required();
  app.add_option("--side", side,
                 "Side of the square area in metres (default: 100 points per square metre)");
  app.add_option("--seed", seed, "Random seed");
  app.add_option("-o,--output", output, "Output .las")->required();
  CLI11_PARSE(app, argc, argv);
  if (side <= 0) side = std::sqrt(double(points) / 100.0);

  // Shapes first: their sizes decide how many points the ground keeps.
  glint::edges::SynthParams synth;
  synth.seed = seed;
  synth.min_points = 20000;
  synth.max_points = 200000;
  synth.noise_levels = {0.0, 0.05};
  synth.outlier_probability = 0.0;
  const auto part_budget = static_cast<std::uint64_t>(double(points) * kPartShare);
  const double density = double(points) / (side * side);  // points per square metre
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  struct Part {
    std::uint64_t index;
    double x, y;
  };
  std::vector<Part> parts;
  {
    std::uint64_t planned = 0, index = 0;
    while (planned < part_budget) {
      parts.push_back({index++, uniform(rng) * side, uniform(rng) * side});
      planned += kMeanShapePoints;
    }
  }
  const std::uint64_t part_points_estimate = parts.size() * kMeanShapePoints;
  const std::uint64_t ground_points =
      points > part_points_estimate ? points - part_points_estimate : points / 2;
  const std::uint64_t ground_blocks = (ground_points + kBlockPoints - 1) / kBlockPoints;

  // One block: kBlockPoints of ground, or one shape.
  auto generate_block = [&](std::uint64_t b, std::vector<Record>& records) {
    std::mt19937_64 block_rng(seed * 1000003 + b);
    std::normal_distribution<double> noise(0.0, 0.01);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    auto quantise = [](double value) {
      return static_cast<std::int32_t>(std::llround(value / kScale));
    };
    if (b < ground_blocks) {
      records.resize(std::min<std::uint64_t>(kBlockPoints, ground_points - b * kBlockPoints));
      for (Record& r : records) {
        const double x = u(block_rng) * side, y = u(block_rng) * side;
        const double z = ground_height(x, y) + noise(block_rng);
        r = {{quantise(x), quantise(y), quantise(z + 100.0)},
             static_cast<std::uint16_t>(u(block_rng) * 2000),
             2};
      }
      return;
    }
    const Part& part = parts[b - ground_blocks];
    const glint::edges::SynthCloud shape = glint::edges::synthesize_cloud(synth, part.index);
    const glint::PointCloud& cloud = shape.cloud;
    const std::vector<std::uint8_t>* labels = cloud.get<std::uint8_t>("label");
    float lo[3] = {1e30f, 1e30f, 1e30f}, hi[3] = {-1e30f, -1e30f, -1e30f};
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const float p[3] = {cloud.x[i], cloud.y[i], cloud.z[i]};
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], p[a]), hi[a] = std::max(hi[a], p[a]);
    }
    // Sized so that the shape's surface (about three squares of its largest extent) carries
    // the ground's density.
    const double extent = std::max({hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2], 1e-6f});
    const double s = std::sqrt(double(cloud.size()) / (3.0 * density)) / extent;
    const double base = ground_height(part.x, part.y);
    records.resize(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const double x = part.x + (cloud.x[i] - 0.5 * (lo[0] + hi[0])) * s;
      const double y = part.y + (cloud.y[i] - 0.5 * (lo[1] + hi[1])) * s;
      const double z = base + (cloud.z[i] - lo[2]) * s;
      // Intensity carries the shape's ground-truth label (1000 + 500 * label).
      records[i] = {{quantise(std::clamp(x, 0.0, side)), quantise(std::clamp(y, 0.0, side)),
                     quantise(z + 100.0)},
                    static_cast<std::uint16_t>(1000 + 500 * (labels ? (*labels)[i] : 0)),
                    6};
    }
  };

  // Generated in parallel a batch of blocks at a time and written in order; the point count
  // and bounding box go into the header at the end.
  const std::uint64_t blocks = ground_blocks + parts.size();
  const double scale[3] = {kScale, kScale, kScale}, zero[3] = {0, 0, 0};
  glint::io::LasHeader header = glint::io::make_las_header(4, 6, 0, 0, scale, kOffset, zero, zero);
  glint::io::LasWriter writer(output, "survey", header, true);
  std::int32_t lo[3] = {INT32_MAX, INT32_MAX, INT32_MAX}, hi[3] = {INT32_MIN, INT32_MIN, INT32_MIN};
  std::vector<std::uint8_t> bytes;
  std::uint64_t written = 0;
  constexpr std::uint64_t kBatch = 8;
  for (std::uint64_t batch = 0; batch < blocks; batch += kBatch) {
    std::vector<std::vector<Record>> generated(std::min(kBatch, blocks - batch));
    glint::parallel_for(generated.size(),
                        [&](std::size_t j) { generate_block(batch + j, generated[j]); });
    for (const auto& records : generated) {
      bytes.resize(records.size() * header.record_length);
      for (std::size_t i = 0; i < records.size(); ++i) {
        encode(records[i], written + i, bytes.data() + i * header.record_length);
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::min(lo[a], records[i].xyz[a]), hi[a] = std::max(hi[a], records[i].xyz[a]);
        }
      }
      writer.write_records(written, records.size(), bytes.data());
      written += records.size();
    }
  }
  double min[3], max[3];
  for (int a = 0; a < 3; ++a) {
    min[a] = lo[a] * kScale + kOffset[a];
    max[a] = hi[a] * kScale + kOffset[a];
  }
  writer.set_count_and_bounds(written, min, max);
  writer.commit();
  std::printf("%s: %llu points (%zu shapes) over %.0f m x %.0f m, offset (%.0f, %.0f)\n",
              output.c_str(), static_cast<unsigned long long>(written), parts.size(), side, side,
              kOffset[0], kOffset[1]);
  return 0;
}
