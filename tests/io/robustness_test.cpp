// Damaged input never crashes a reader: it reads, or it throws glint::Error.
#include <gtest/gtest.h>

#include <filesystem>
#include <random>
#include <string>

#include "core/error.h"
#include "io/ply.h"
#include "io/point_cloud_io.h"
#include "io_test_support.h"

namespace glint::io {
namespace {

// Reads every prefix of the file's bytes and copies with a few random bytes replaced.
void read_damaged_copies(const std::string& source, int trials) {
  const std::string bytes = test::read_text(source);
  const std::string extension = std::filesystem::path(source).extension().string();
  int copies = 0;
  auto read = [&](const std::string& content) {
    // A new file each time: rewriting one file is slow on some file systems.
    const std::string path = test::scratch("damaged" + std::to_string(copies++) + extension);
    test::write_text(path, content);
    try {
      read_point_cloud(path);
    } catch (const Error&) {
    }
    std::filesystem::remove(path);
  };
  for (std::size_t length = 0; length < bytes.size(); ++length) read(bytes.substr(0, length));
  std::mt19937 random(7);
  for (int trial = 0; trial < trials; ++trial) {
    std::string damaged = bytes;
    for (int replaced = 0; replaced < 3; ++replaced) {
      damaged[random() % damaged.size()] = static_cast<char>(random());
    }
    read(damaged);
  }
}

TEST(Robustness, DamagedPlyFiles) {
  PointCloud cloud;
  cloud.push_back(1, 2, 3);
  cloud.push_back(4, 5, 6);
  cloud.set("label", std::vector<std::uint8_t>{1, 2});
  cloud.set("weight", std::vector<double>{0.5, 0.25});
  const std::string written = test::scratch("valid.ply");
  write_ply(written, cloud, PlyFormat::binary_big_endian);
  read_damaged_copies(written, 200);
  read_damaged_copies(test::fixture("ascii_faces.ply"), 200);
  read_damaged_copies(test::fixture("little_endian_aliases.ply"), 200);
  read_damaged_copies(test::fixture("big_endian_double.ply"), 200);
}

TEST(Robustness, DamagedPcdFiles) {
  read_damaged_copies(test::fixture("organised.pcd"), 200);
  read_damaged_copies(test::fixture("binary_rgb.pcd"), 200);
}

TEST(Robustness, DamagedTextFiles) {
  read_damaged_copies(test::fixture("labelled.xyz"), 200);
  read_damaged_copies(test::fixture("count_first.pts"), 200);
}

}  // namespace
}  // namespace glint::io
