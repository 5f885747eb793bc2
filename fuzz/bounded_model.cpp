// BoundED model files (edges/model.h): configuration, standardisation and every layer's shape.
#include "edges/model.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path =
      glint::fuzz::write_scratch_file("model.json", glint::fuzz::bytes(data, size));
  glint::fuzz::parse_or_reject([&] { glint::edges::Model::load(path); });
  return 0;
}
