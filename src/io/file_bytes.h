#pragma once
// Whole-file reads for the parsers (one read, then parsing from memory).
#include <string>

namespace glint::io {

// The file's bytes; throws glint::Error(path, "", reason) when it cannot be opened or read.
std::string read_file_bytes(const std::string& path);

}  // namespace glint::io
