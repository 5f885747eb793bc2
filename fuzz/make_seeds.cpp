// Writes the seed inputs of the fuzz targets that have no small fixture in tests/data: LAS
// files, EXR / HDR / PNG images, .npy arrays, scene.json, lights.json and small BoundED and
// HemiCNN model files, all made by glint's own writers so that they are valid inputs.
// Usage: fuzz_make_seeds CORPUS_FOLDER   (writes CORPUS_FOLDER/<target>/seed-*)
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "core/error.h"
#include "edges/model.h"
#include "io/image_io.h"
#include "io/las.h"
#include "io/npy.h"
#include "reflectance/hemicnn.h"
#include "reflectance/light_estimation.h"
#include "render/builtin_scenes.h"
#include "render/scene_json.h"

namespace {

using namespace glint;

void write_bytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

std::vector<std::uint8_t> vlr(const char* user, std::uint16_t record_id,
                              const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> bytes(54 + payload.size(), 0);
  std::memcpy(bytes.data() + 2, user, std::strlen(user));
  std::memcpy(bytes.data() + 18, &record_id, 2);
  const auto length = static_cast<std::uint16_t>(payload.size());
  std::memcpy(bytes.data() + 20, &length, 2);
  std::copy(payload.begin(), payload.end(), bytes.begin() + 54);
  return bytes;
}

// Four points of `format` in LAS 1.`minor`, with a described ushort Extra Bytes field and, in
// 1.4, one EVLR.
void write_las(const std::string& path, int minor, int format) {
  const std::size_t n = 4;
  const double scale[3] = {0.01, 0.01, 0.01}, offset[3] = {1000, 2000, 0};
  const double low[3] = {990, 1990, -1}, high[3] = {1010, 2010, 1};
  io::LasHeader header = io::make_las_header(minor, format, 2, n, scale, offset, low, high);
  std::vector<std::uint8_t> descriptor(192, 0);
  descriptor[2] = 3;  // ushort
  std::memcpy(descriptor.data() + 4, "my_short", 8);
  header.vlr_bytes = vlr("LASF_Spec", 4, descriptor);
  header.vlr_count = 1;
  header.offset_to_points = header.header_bytes.size() + header.vlr_bytes.size();
  if (minor >= 4) {
    std::vector<std::uint8_t> evlr(60 + 5, 0x5A);
    const std::uint64_t length = 5;
    std::memcpy(evlr.data() + 20, &length, 8);
    header.evlr_bytes = evlr;
    header.evlr_count = 1;
    header.evlr_start = header.offset_to_points + n * header.record_length;
    const std::uint32_t count = 1;
    std::memcpy(header.header_bytes.data() + 243, &count, 4);
  }
  std::vector<std::uint8_t> records(n * header.record_length, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const std::int32_t xyz[3] = {int(i) * 100 - 150, int(i % 2) * 300, int(i) - 2};
    std::memcpy(records.data() + i * header.record_length, xyz, 12);
  }
  io::LasWriter writer(path, "seed", header, true);
  writer.write_records(0, n, records.data());
  writer.commit();
}

ImageF gradient(int width, int height, int channels) {
  ImageF image(width, height, channels);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < channels; ++c)
        image.at(x, y, c) = float(x + 2 * y + c) / float(width + 2 * height + channels);
  return image;
}

}  // namespace

int main(int argc, char** argv) try {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s CORPUS_FOLDER\n", argv[0]);
    return 2;
  }
  const std::string corpus = argv[1];
  for (const char* target :
       {"las", "image", "npy", "scene_json", "lights_json", "bounded_model", "hemicnn_model"})
    std::filesystem::create_directories(corpus + "/" + target);

  write_las(corpus + "/las/seed-1.2-format0.las", 2, 0);
  write_las(corpus + "/las/seed-1.3-format3.las", 3, 3);
  write_las(corpus + "/las/seed-1.4-format6.las", 4, 6);
  write_las(corpus + "/las/seed-1.4-format10.las", 4, 10);

  io::write_image(corpus + "/image/seed-rgb8.png", gradient(5, 4, 3));
  io::write_image(corpus + "/image/seed-grey16.png", gradient(4, 3, 1), io::PngDepth::sixteen);
  io::write_image(corpus + "/image/seed-rgba8.png", gradient(3, 3, 4));
  io::write_image(corpus + "/image/seed-rgb.exr", gradient(4, 3, 3));
  io::write_image(corpus + "/image/seed-grey.exr", gradient(3, 2, 1));
  {  // Radiance RGBE, as environment maps come (OpenCV's encoder; glint writes no .hdr)
    cv::Mat hdr(3, 4, CV_32FC3, cv::Scalar(0.5, 2.0, 8.0));
    cv::imwrite(corpus + "/image/seed-env.hdr", hdr);
  }

  io::write_image(corpus + "/npy/seed-hw.npy", gradient(4, 3, 1));
  io::write_image(corpus + "/npy/seed-hwc.npy", gradient(3, 2, 5));
  {  // float64, which read_npy converts
    std::string header = "{'descr': '<f8', 'fortran_order': False, 'shape': (2, 2), }";
    header.append((64 - (10 + header.size() + 1) % 64) % 64, ' ');  // 64-byte aligned data
    header += '\n';
    std::string file = std::string("\x93NUMPY\x01\x00", 8);
    file += char(header.size() & 0xff);
    file += char(header.size() >> 8);
    file += header;
    for (double value : {0.25, -1.5, 3.0, 1e-3}) file.append(reinterpret_cast<char*>(&value), 8);
    write_bytes(corpus + "/npy/seed-f8.npy", file);
  }

  render::BuiltinOptions builtin;
  builtin.frames = 2;
  builtin.data_dir = "/nonexistent";  // the file paths are kept as text, not opened here
  for (const std::string& name : {std::string("cubes")}) {
    render::write_scene_json(corpus + "/scene_json/seed-" + name + ".json",
                             render::make_builtin_scene(name, builtin));
  }

  reflectance::LightEstimate lights;
  lights.lights.push_back({{0.5, 2.0, -1.0}, {4.5, 4.0, 3.5}, 0.05});
  lights.lights.push_back({{-1.0, 1.5, 0.5}, {12, 12, 12}, 0.05});
  lights.support = {{12, 340.5, 0.01, 0.0}, {3, 20, 0.2, 0.1}};
  lights.capture = "capture";
  lights.exposure = 5e-4f;
  reflectance::write_lights_json(corpus + "/lights_json/seed-two.json", lights);

  // Small architectures keep the files (and every fuzzing run) small; the loader's checks are
  // the same at any size.
  edges::ModelConfig bounded;
  bounded.scales = {16, 8};
  bounded.fusion_width = 3;
  bounded.hidden = 4;
  bounded.hidden_layers = 1;
  write_bytes(corpus + "/bounded_model/seed-3c.json", edges::Model(bounded).to_json().dump());
  bounded.classes = 2;
  bounded.hidden_layers = 2;
  write_bytes(corpus + "/bounded_model/seed-2c.json", edges::Model(bounded).to_json().dump());

  reflectance::HemiCnnConfig hemicnn;
  hemicnn.image_size = 5;
  hemicnn.conv_channels = {2, 2};
  hemicnn.branch_features = 4;
  hemicnn.head_hidden = 4;
  write_bytes(corpus + "/hemicnn_model/seed-small.json",
              reflectance::HemiCnn(hemicnn).to_json().dump());
  return 0;
} catch (const std::exception& error) {
  std::fprintf(stderr, "fuzz_make_seeds: %s\n", error.what());
  return 1;
}
