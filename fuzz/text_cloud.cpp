// Text point clouds: .xyz/.csv (whitespace or comma separated, optional header line) and .pts
// (which may start with a point-count line); the same bytes are read as both.
#include "io/text_cloud.h"

#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  for (const char* name : {"input.xyz", "input.pts"}) {
    const std::string path = glint::fuzz::write_scratch_file(name, glint::fuzz::bytes(data, size));
    glint::fuzz::parse_or_reject([&] { glint::io::read_text_cloud(path); });
  }
  return 0;
}
