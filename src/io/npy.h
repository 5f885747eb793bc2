#pragma once
// NumPy .npy (format 1.0/2.0) arrays of float32 or float64, C order: features, material maps
// with any number of channels.
#include <cstddef>
#include <string>
#include <vector>

namespace glint::io {

struct NpyArray {
  std::vector<std::size_t> shape;
  std::vector<float> values;  // C order (last index fastest)
};

// Writes float32 little-endian; atomic (temporary + rename). Throws glint::Error naming `path`.
void write_npy(const std::string& path, const std::vector<std::size_t>& shape, const float* values);

// Reads '<f4' or '<f8' (converted to float), C order. A truncated file, another dtype, Fortran
// order or a malformed header -> glint::Error naming `path` and the problem.
NpyArray read_npy(const std::string& path);

}  // namespace glint::io
