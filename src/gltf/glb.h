#pragma once
// The glTF 2.0 binary container (GLB, glTF 2.0 spec §4.4): a 12-byte header, the JSON chunk and
// one BIN chunk. GlbBuilder appends buffer views and accessors to the BIN chunk as a document is
// assembled; read_glb() parses a file back (the round-trip tests and `glint export`'s checks).
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

namespace glint::gltf {

// glTF's accessor component types and buffer-view targets (spec §5.1.3, §5.11.5).
inline constexpr int kUnsignedInt = 5125, kFloat = 5126;
inline constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

class GlbBuilder {
 public:
  // Starts a document with "asset" (version 2.0, generator glint) and one buffer.
  GlbBuilder();

  nlohmann::json& document() { return document_; }
  const nlohmann::json& document() const { return document_; }

  // Appends `bytes` to the BIN chunk, 4-byte aligned, as a new buffer view (`target` 0: none,
  // e.g. an image); returns its index.
  int add_buffer_view(std::span<const std::uint8_t> bytes, int target = 0);
  // A float accessor of `count` elements of `components` values ("SCALAR", "VEC2", "VEC3",
  // "VEC4") over a new vertex buffer view, with the per-component min and max that POSITION
  // needs when `min_max`; returns the accessor's index.
  int add_float_accessor(std::span<const float> values, int components, bool min_max = false);
  // A SCALAR unsigned-int index accessor over a new element-array buffer view.
  int add_index_accessor(std::span<const std::uint32_t> indices);

  // The whole file: header, JSON chunk (space-padded), BIN chunk (zero-padded).
  std::vector<std::uint8_t> bytes() const;
  // bytes() written atomically (io/atomic_file.h); throws glint::Error naming `path`.
  void write(const std::string& path) const;

 private:
  nlohmann::json document_;
  std::vector<std::uint8_t> bin_;
};

struct Glb {
  nlohmann::json document;
  std::vector<std::uint8_t> bin;
};

// Parses a GLB: magic, version 2, chunk lengths and types, the JSON. Throws glint::Error naming
// `path` and what is wrong (a truncated file, a chunk past the end, a JSON syntax error).
Glb parse_glb(std::span<const std::uint8_t> bytes, const std::string& path);
Glb read_glb(const std::string& path);

// The values of accessor `index` (float or unsigned-int components, tightly packed, as
// GlbBuilder writes them), widened to double; throws glint::Error for anything else or a view
// outside the BIN chunk.
std::vector<double> accessor_values(const Glb& glb, int index);

}  // namespace glint::gltf
