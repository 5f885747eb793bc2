#pragma once
// Shared by the libFuzzer targets. glint's readers take paths (they read whole files, or seek in
// them), so each input is written to a per-process scratch folder and the real entry point reads
// it from there: the fuzzer exercises exactly the code a user's file reaches.
//
// A target rejects a bad input by throwing glint::Error; that is the expected outcome and is
// swallowed here. Every other exception, abort or sanitizer report is a finding.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/error.h"

namespace glint::fuzz {

// The fuzzer's bytes.
inline std::string_view bytes(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

// A folder under the system temporary folder ($TMPDIR), made on first use and removed at exit.
const std::string& scratch_folder();

// Writes `data` to scratch_folder()/name (replacing it) and returns the path.
std::string write_scratch_file(const std::string& name, std::string_view data);

// Runs `parse`, accepting glint::Error as the clean rejection of a bad input.
template <class Parse>
void parse_or_reject(Parse&& parse) {
  try {
    parse();
  } catch (const glint::Error&) {
  }
}

// Splits `data` at lines holding only "====" into at most `count` sections (the last one keeps
// any further separators); sections that are absent come back empty. The multi-file inputs
// (an RGB-D folder's index files) are written this way, one file per section.
std::vector<std::string_view> split_sections(std::string_view data, std::size_t count);

}  // namespace glint::fuzz
