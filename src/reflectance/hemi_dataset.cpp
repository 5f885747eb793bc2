#include "reflectance/hemi_dataset.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "io/json_fields.h"
#include "io/json_report.h"
#include "io/npy.h"

namespace glint::reflectance {
namespace {

constexpr const char* kFormatName = "glint-hemi-dataset";
constexpr int kFormatVersion = 1;

// Throws glint::Error(where, element, ...) unless the material is a valid Ward material.
void check_material(const render::WardMaterial& m, const std::string& where,
                    const std::string& element) {
  const bool valid = m.kd.allFinite() && m.ks.allFinite() && (m.kd.array() >= 0).all() &&
                     (m.ks.array() >= 0).all() && std::isfinite(m.alpha) && m.alpha > 0;
  if (!valid)
    throw Error(where, element,
                fmt::format("invalid Ward material kd ({}, {}, {}) ks ({}, {}, {}) alpha {}: "
                            "albedos must be finite and >= 0, alpha finite and > 0",
                            m.kd.x(), m.kd.y(), m.kd.z(), m.ks.x(), m.ks.y(), m.ks.z(), m.alpha));
}

void check_size(int size, const std::string& where) {
  if (size < kMinHemiImageSize || size > kMaxHemiImageSize)
    throw Error(where, "size",
                fmt::format("hemi-image size {} is outside [{}, {}]", size, kMinHemiImageSize,
                            kMaxHemiImageSize));
}

// Reads seq file `path`, expecting [M, 3, size, size] finite floats.
void read_sequence_images(const std::string& path, int size, HemiSequence& sequence) {
  io::NpyArray array = io::read_npy(path);
  const std::size_t side = static_cast<std::size_t>(size);
  if (array.shape.size() != 4 || array.shape[1] != 3 || array.shape[2] != side ||
      array.shape[3] != side) {
    std::string shape;
    for (std::size_t extent : array.shape)
      shape += (shape.empty() ? "" : ", ") + std::to_string(extent);
    throw Error(path, "shape",
                fmt::format("expected [M, 3, {}, {}] (M hemi-images of the index's size {}), "
                            "found [{}]",
                            size, size, size, shape));
  }
  if (array.shape[0] < static_cast<std::size_t>(kMinHemiImages) ||
      array.shape[0] > static_cast<std::size_t>(kMaxHemiImages))
    throw Error(path, "shape",
                fmt::format("{} hemi-images; a sequence needs {} to {}", array.shape[0],
                            kMinHemiImages, kMaxHemiImages));
  const std::size_t image_floats = 3 * side * side;
  for (std::size_t i = 0; i < array.values.size(); ++i)
    if (!std::isfinite(array.values[i]))
      throw Error(path, fmt::format("hemi-image {}", i / image_floats), "non-finite value");
  sequence.images = static_cast<int>(array.shape[0]);
  sequence.values = std::move(array.values);
}

bool target_matches(const render::PerceptualWard& stored, const render::PerceptualWard& expected) {
  auto close = [](float a, float b) {
    return std::fabs(a - b) <= 1e-3f * std::max(1.0f, std::fabs(b));
  };
  for (int i = 0; i < 3; ++i)
    if (!close(stored.lab[i], expected.lab[i]) || !close(stored.c[i], expected.c[i])) return false;
  return close(stored.d, expected.d);
}

}  // namespace

HemiDataset read_hemi_dataset(const std::string& directory) {
  const std::filesystem::path folder(directory);
  const std::string index_path = (folder / "index.json").string();
  if (!std::filesystem::is_regular_file(index_path))
    throw Error(index_path, "", "missing: not a HemiCNN dataset folder (no index.json)");
  const io::JsonFields reader(index_path);
  const nlohmann::json root = reader.read_document(kFormatName, kFormatVersion);

  HemiDataset dataset;
  dataset.directory = directory;
  const nlohmann::json& size = reader.member(root, "size", "");
  if (!size.is_number_integer()) reader.fail("size", "expected an integer");
  dataset.size = size.get<int>();
  check_size(dataset.size, index_path);
  dataset.projection = parse_hemi_projection(reader.string(root, "projection", ""), index_path);
  if (root.contains("input"))
    dataset.input = parse_hemi_input(reader.string(root, "input", ""), index_path);

  const nlohmann::json& entries = reader.member(root, "sequences", "");
  if (!entries.is_array()) reader.fail("sequences", "expected an array");
  if (entries.empty()) reader.fail("sequences", "no sequences");
  dataset.sequences.resize(entries.size());
  for (std::size_t s = 0; s < entries.size(); ++s) {
    const nlohmann::json& entry = entries[s];
    const std::string where = fmt::format("sequences[{}]", s);
    HemiSequence& sequence = dataset.sequences[s];
    sequence.file = reader.string(entry, "file", where);
    if (sequence.file.empty() || std::filesystem::path(sequence.file).has_parent_path())
      reader.fail(where + ".file", "expected a file name inside the dataset folder");
    sequence.source = reader.string(entry, "source", where);
    const std::vector<float> kd = reader.floats(entry, "kd", 3, where);
    const std::vector<float> ks = reader.floats(entry, "ks", 3, where);
    sequence.material.kd = Eigen::Vector3f(kd[0], kd[1], kd[2]);
    sequence.material.ks = Eigen::Vector3f(ks[0], ks[1], ks[2]);
    sequence.material.alpha =
        reader.finite_float(reader.member(entry, "alpha", where), where + ".alpha");
    check_material(sequence.material, index_path, where);
    const std::vector<float> target = reader.floats(entry, "target", 7, where);
    sequence.target.lab = Eigen::Vector3f(target[0], target[1], target[2]);
    sequence.target.c = Eigen::Vector3f(target[3], target[4], target[5]);
    sequence.target.d = target[6];
    if (!target_matches(sequence.target, render::to_perceptual(sequence.material)))
      reader.fail(where + ".target",
                  "is not the perceptual form (render::to_perceptual) of its kd, ks and alpha");
    read_sequence_images((folder / sequence.file).string(), dataset.size, sequence);
  }
  return dataset;
}

HemiDatasetWriter::HemiDatasetWriter(std::string directory, int size, HemiProjection projection,
                                     HemiInput input)
    : directory_(std::move(directory)), size_(size), projection_(projection), input_(input) {
  check_size(size, directory_);
  std::error_code error;
  std::filesystem::create_directories(directory_, error);
  if (error) throw Error(directory_, "", "cannot create the dataset folder: " + error.message());
}

int HemiDatasetWriter::add_sequence(const float* images, int count,
                                    const render::WardMaterial& material,
                                    const std::string& source) {
  const int index = sequence_count();
  HemiSequence entry;
  entry.file = fmt::format("seq_{:05d}.npy", index);
  const std::string path = (std::filesystem::path(directory_) / entry.file).string();
  if (count < kMinHemiImages || count > kMaxHemiImages)
    throw Error(path, "",
                fmt::format("{} hemi-images; a sequence needs {} to {}", count, kMinHemiImages,
                            kMaxHemiImages));
  check_material(material, path, "material");
  const std::size_t image_floats = 3 * static_cast<std::size_t>(size_) * size_;
  for (std::size_t i = 0; i < image_floats * count; ++i)
    if (!std::isfinite(images[i]))
      throw Error(path, fmt::format("hemi-image {}", i / image_floats), "non-finite value");
  const std::size_t side = static_cast<std::size_t>(size_);
  io::write_npy(path, {static_cast<std::size_t>(count), 3, side, side}, images);
  entry.source = source;
  entry.material = material;
  entry.target = render::to_perceptual(material);
  entry.images = count;
  entries_.push_back(std::move(entry));
  return index;
}

void HemiDatasetWriter::finish() {
  nlohmann::json sequences = nlohmann::json::array();
  for (const HemiSequence& entry : entries_) {
    const render::PerceptualWard& t = entry.target;
    const float target[] = {t.lab.x(), t.lab.y(), t.lab.z(), t.c.x(), t.c.y(), t.c.z(), t.d};
    sequences.push_back({{"file", entry.file},
                         {"target", io::exact_float_array(target, 7)},
                         {"kd", io::exact_float_array(entry.material.kd.data(), 3)},
                         {"ks", io::exact_float_array(entry.material.ks.data(), 3)},
                         {"alpha", io::exact_float(entry.material.alpha)},
                         {"source", entry.source}});
  }
  io::write_json((std::filesystem::path(directory_) / "index.json").string(),
                 {{"format", kFormatName},
                  {"version", kFormatVersion},
                  {"size", size_},
                  {"projection", hemi_projection_name(projection_)},
                  {"input", hemi_input_name(input_)},
                  {"sequences", sequences}});
}

}  // namespace glint::reflectance
