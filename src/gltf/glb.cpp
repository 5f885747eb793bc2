#include "gltf/glb.h"

#include <algorithm>
#include <cstring>
#include <limits>

#include "core/error.h"
#include "io/atomic_file.h"
#include "io/file_bytes.h"

namespace glint::gltf {
namespace {

constexpr std::uint32_t kMagic = 0x46546C67;  // "glTF"
constexpr std::uint32_t kJsonChunk = 0x4E4F534A, kBinChunk = 0x004E4942;

void put_u32(std::vector<std::uint8_t>& out, std::uint32_t value) {
  for (int k = 0; k < 4; ++k) out.push_back(std::uint8_t(value >> (8 * k)));
}

std::uint32_t get_u32(std::span<const std::uint8_t> bytes, std::size_t at) {
  std::uint32_t value = 0;
  for (int k = 0; k < 4; ++k) value |= std::uint32_t(bytes[at + k]) << (8 * k);
  return value;
}

std::size_t padded(std::size_t n) { return (n + 3) & ~std::size_t(3); }

}  // namespace

GlbBuilder::GlbBuilder() {
  document_["asset"] = {{"version", "2.0"}, {"generator", "glint"}};
  document_["buffers"] = nlohmann::json::array({{{"byteLength", 0}}});
}

int GlbBuilder::add_buffer_view(std::span<const std::uint8_t> bytes, int target) {
  bin_.resize(padded(bin_.size()), 0);
  nlohmann::json view = {{"buffer", 0}, {"byteOffset", bin_.size()}, {"byteLength", bytes.size()}};
  if (target != 0) view["target"] = target;
  bin_.insert(bin_.end(), bytes.begin(), bytes.end());
  document_["buffers"][0]["byteLength"] = padded(bin_.size());
  nlohmann::json& views = document_["bufferViews"];
  views.push_back(std::move(view));
  return int(views.size()) - 1;
}

int GlbBuilder::add_float_accessor(std::span<const float> values, int components, bool min_max) {
  static const char* const kTypes[] = {"SCALAR", "VEC2", "VEC3", "VEC4"};
  if (components < 1 || components > 4 || values.size() % components != 0)
    throw Error("glTF", "accessor", "float values do not fill whole elements");
  const int view = add_buffer_view(
      {reinterpret_cast<const std::uint8_t*>(values.data()), values.size_bytes()}, kArrayBuffer);
  nlohmann::json accessor = {{"bufferView", view},
                             {"componentType", kFloat},
                             {"count", values.size() / components},
                             {"type", kTypes[components - 1]}};
  if (min_max) {
    std::vector<float> lo(components, std::numeric_limits<float>::max());
    std::vector<float> hi(components, std::numeric_limits<float>::lowest());
    for (std::size_t i = 0; i < values.size(); ++i) {
      lo[i % components] = std::min(lo[i % components], values[i]);
      hi[i % components] = std::max(hi[i % components], values[i]);
    }
    accessor["min"] = lo;
    accessor["max"] = hi;
  }
  nlohmann::json& accessors = document_["accessors"];
  accessors.push_back(std::move(accessor));
  return int(accessors.size()) - 1;
}

int GlbBuilder::add_index_accessor(std::span<const std::uint32_t> indices) {
  const int view =
      add_buffer_view({reinterpret_cast<const std::uint8_t*>(indices.data()), indices.size_bytes()},
                      kElementArrayBuffer);
  nlohmann::json& accessors = document_["accessors"];
  accessors.push_back({{"bufferView", view},
                       {"componentType", kUnsignedInt},
                       {"count", indices.size()},
                       {"type", "SCALAR"}});
  return int(accessors.size()) - 1;
}

std::vector<std::uint8_t> GlbBuilder::bytes() const {
  std::string json = document_.dump();
  json.resize(padded(json.size()), ' ');
  const std::size_t bin_size = padded(bin_.size());
  std::vector<std::uint8_t> out;
  out.reserve(12 + 8 + json.size() + 8 + bin_size);
  put_u32(out, kMagic);
  put_u32(out, 2);
  put_u32(out, std::uint32_t(12 + 8 + json.size() + (bin_.empty() ? 0 : 8 + bin_size)));
  put_u32(out, std::uint32_t(json.size()));
  put_u32(out, kJsonChunk);
  out.insert(out.end(), json.begin(), json.end());
  if (!bin_.empty()) {
    put_u32(out, std::uint32_t(bin_size));
    put_u32(out, kBinChunk);
    out.insert(out.end(), bin_.begin(), bin_.end());
    out.resize(out.size() + bin_size - bin_.size(), 0);
  }
  return out;
}

void GlbBuilder::write(const std::string& path) const {
  const std::vector<std::uint8_t> data = bytes();
  io::AtomicFile file(path);
  file.stream().write(reinterpret_cast<const char*>(data.data()), std::streamsize(data.size()));
  file.commit();
}

Glb parse_glb(std::span<const std::uint8_t> bytes, const std::string& path) {
  if (bytes.size() < 20 || get_u32(bytes, 0) != kMagic)
    throw Error(path, "header", "not a GLB file (no glTF magic)");
  if (get_u32(bytes, 4) != 2) throw Error(path, "header", "GLB version is not 2");
  const std::size_t length = get_u32(bytes, 8);
  if (length > bytes.size()) throw Error(path, "header", "file is shorter than its stated length");
  Glb glb;
  bool has_json = false;
  for (std::size_t at = 12; at + 8 <= length;) {
    const std::size_t size = get_u32(bytes, at), type = get_u32(bytes, at + 4);
    if (at + 8 + size > length) throw Error(path, "chunk", "chunk runs past the end of the file");
    const auto data = bytes.subspan(at + 8, size);
    if (type == kJsonChunk) {
      try {
        glb.document = nlohmann::json::parse(data.begin(), data.end());
      } catch (const nlohmann::json::exception& e) {
        throw Error(path, "JSON chunk", e.what());
      }
      has_json = true;
    } else if (type == kBinChunk) {
      glb.bin.assign(data.begin(), data.end());
    }
    at += 8 + padded(size);
  }
  if (!has_json) throw Error(path, "JSON chunk", "missing");
  return glb;
}

Glb read_glb(const std::string& path) {
  const std::string data = io::read_file_bytes(path);
  return parse_glb({reinterpret_cast<const std::uint8_t*>(data.data()), data.size()}, path);
}

std::vector<double> accessor_values(const Glb& glb, int index) {
  const std::string element = "accessor " + std::to_string(index);
  const nlohmann::json& accessors = glb.document.at("accessors");
  if (index < 0 || index >= int(accessors.size())) throw Error("GLB", element, "does not exist");
  const nlohmann::json& accessor = accessors[index];
  const nlohmann::json& view = glb.document.at("bufferViews").at(int(accessor.at("bufferView")));
  const std::string type = accessor.at("type");
  const int components = type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : 4;
  const int component_type = accessor.at("componentType");
  if (component_type != kFloat && component_type != kUnsignedInt)
    throw Error("GLB", element, "component type is neither float nor unsigned int");
  const std::size_t count = std::size_t(accessor.at("count")) * components;
  const std::size_t offset =
      std::size_t(view.value("byteOffset", 0)) + std::size_t(accessor.value("byteOffset", 0));
  if (offset + 4 * count > glb.bin.size()) throw Error("GLB", element, "outside the BIN chunk");
  std::vector<double> values(count);
  for (std::size_t i = 0; i < count; ++i) {
    std::uint32_t raw = get_u32(glb.bin, offset + 4 * i);
    if (component_type == kUnsignedInt) {
      values[i] = raw;
    } else {
      float f;
      std::memcpy(&f, &raw, 4);
      values[i] = f;
    }
  }
  return values;
}

}  // namespace glint::gltf
