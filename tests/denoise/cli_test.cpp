// `glint denoise` end to end: noise-map -> run (NLM and a few-iteration neural run through the
// plugin) -> eval, and the error contract for bad inputs (one line naming the file, exit 1, no
// output left behind).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "denoise/corruption.h"
#include "denoise/test_patterns.h"
#include "io/image_io.h"
#include "support/cli_fixture.h"

namespace glint {
namespace {

namespace fs = std::filesystem;

class DenoiseCliTest : public CliTest {
 protected:
  void SetUp() override {
    CliTest::SetUp();
    const ImageF clean = denoise::step_gradient_pattern(48, 40, 3, 4);
    const ImageF mask = denoise::blob_mask(48, 40, 0.3, 4);
    io::write_image(path("clean.png"), clean);
    io::write_image(path("noisy.png"), denoise::add_noise_in_mask(clean, mask, 0.2, 4));
  }
};

TEST_F(DenoiseCliTest, NoiseMapRunAndEval) {
  const CommandResult map =
      glint("denoise noise-map " + path("noisy.png") + " -o " + path("m.png") + " --raw " +
            path("n.exr") + " --report " + path("map.json"));
  ASSERT_EQ(map.exit_code, 0) << map.output;
  const ImageF guidance = io::read_image(path("m.png"));
  EXPECT_EQ(guidance.width(), 48);
  EXPECT_EQ(guidance.channels(), 1);
  EXPECT_EQ(io::read_image(path("n.exr")).channels(), 1);

  const CommandResult nlm =
      glint("denoise run " + path("noisy.png") + " -o " + path("nlm.png") + " --method nlm");
  ASSERT_EQ(nlm.exit_code, 0) << nlm.output;
  EXPECT_TRUE(io::read_image(path("nlm.png")).same_size(guidance));

  const CommandResult neural =
      glint("denoise run " + path("noisy.png") + " -o " + path("gdip.png") +
            " --method guided-dip --guidance " + path("m.png") +
            " --iterations 4 --levels 2 --channels 8 --device cpu --snapshot-every 2" +
            " --snapshot-dir " + path("snaps") + " --report " + path("run.json"));
  ASSERT_EQ(neural.exit_code, 0) << neural.output;
  EXPECT_TRUE(io::read_image(path("gdip.png")).same_size(guidance));
  EXPECT_TRUE(fs::exists(path("snaps/guided-dip-000004.png")));
  const auto run = nlohmann::json::parse(std::ifstream(path("run.json")));
  EXPECT_EQ(run["iterations"], 4);

  const CommandResult eval =
      glint("denoise eval --images " + path("clean.png") + " --crop 32" +
            " --methods nlm,s2s --iterations 4 --predictions 2 --levels 2 --channels 8" +
            " --trace-every 2 --report " + path("eval.json"));
  ASSERT_EQ(eval.exit_code, 0) << eval.output;
  const auto report = nlohmann::json::parse(std::ifstream(path("eval.json")));
  EXPECT_TRUE(report["summary"].contains("s2s"));
  // --trace-every 2 over 4 iterations: the running estimate scored at 2 and 4.
  const auto& trace = report["images"][0]["methods"]["s2s"]["trace"];
  ASSERT_EQ(trace.size(), 2u);
  EXPECT_EQ(trace[1]["iteration"], 4);
  EXPECT_TRUE(trace[1].contains("psnr_noisy"));
  EXPECT_FALSE(report["summary"]["s2s"].contains("trace"));
  EXPECT_TRUE(report["summary"]["noise map svd"].contains("auc"));
  EXPECT_GT(report["summary"]["nlm"]["psnr"]["mean"].get<double>(), 10.0);
}

TEST_F(DenoiseCliTest, BadInputsGiveOneLineErrors) {
  std::ofstream(path("text.png")) << "not an image";
  const CommandResult unreadable =
      glint("denoise run " + path("text.png") + " -o " + path("out.png") + " --method nlm");
  EXPECT_EQ(unreadable.exit_code, 1);
  EXPECT_NE(unreadable.output.find("text.png"), std::string::npos) << unreadable.output;
  EXPECT_FALSE(fs::exists(path("out.png")));

  io::write_image(path("small.png"), ImageF(20, 20, 1, 0.5f));
  const CommandResult mismatch =
      glint("denoise run " + path("noisy.png") + " -o " + path("out.png") +
            " --method guided-s2s --guidance " + path("small.png"));
  EXPECT_EQ(mismatch.exit_code, 1);
  EXPECT_NE(mismatch.output.find("small.png"), std::string::npos) << mismatch.output;
  EXPECT_NE(mismatch.output.find("20x20"), std::string::npos) << mismatch.output;
  EXPECT_FALSE(fs::exists(path("out.png")));

  const CommandResult missing =
      glint("denoise noise-map " + path("nope.png") + " -o " + path("m.png"));
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_NE(missing.output.find("nope.png"), std::string::npos) << missing.output;
  EXPECT_FALSE(fs::exists(path("m.png")));
}

// A 389-byte PNG declaring 20000x20000 ran for minutes at 2.4 GB; a damaged one printed
// libpng's own line before glint's.
TEST_F(DenoiseCliTest, ImageHeadersAreCheckedAndLibpngSpeaksInGlintsLine) {
  auto big_endian = [](std::uint32_t value) {
    return std::string{char(value >> 24), char(value >> 16), char(value >> 8), char(value)};
  };
  std::ofstream(path("huge.png"), std::ios::binary)
      << std::string("\x89PNG\r\n\x1a\n", 8) << big_endian(13) << "IHDR" << big_endian(20000)
      << big_endian(20000) << std::string("\x08\x02\x00\x00\x00", 5) << big_endian(0)
      << big_endian(0) << "IEND" << big_endian(0xAE426082);
  const CommandResult huge =
      glint("denoise noise-map " + path("huge.png") + " -o " + path("m.png"));
  EXPECT_EQ(huge.exit_code, 1);
  EXPECT_EQ(huge.output, "glint: error: " + path("huge.png") +
                             ": header: 20000x20000 pixels is outside the allowed image size (each "
                             "side 1 to 65535, at most 134217728 pixels in all)\n");
  EXPECT_FALSE(fs::exists(path("m.png")));

  std::string bytes;
  {
    std::ifstream in(path("noisy.png"), std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  const std::size_t data = bytes.find("IDAT") + 8;
  bytes[data] = char(bytes[data] ^ 0x55);
  std::ofstream(path("damaged.png"), std::ios::binary) << bytes;
  const CommandResult damaged =
      glint("denoise noise-map " + path("damaged.png") + " -o " + path("m.png"));
  EXPECT_EQ(damaged.exit_code, 1);
  // One line with libpng's reason (zlib meets the damage before the chunk's CRC is checked).
  EXPECT_EQ(damaged.output.rfind(
                "glint: error: " + path("damaged.png") + ": not a readable PNG: IDAT: ", 0),
            0u)
      << damaged.output;
  EXPECT_EQ(std::count(damaged.output.begin(), damaged.output.end(), '\n'), 1);
}

}  // namespace
}  // namespace glint
