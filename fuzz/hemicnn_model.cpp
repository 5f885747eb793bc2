// HemiCNN model files (reflectance/hemicnn.h): configuration, standardisation and every
// layer's shape.
#include "fuzz_support.h"
#include "reflectance/hemicnn.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path =
      glint::fuzz::write_scratch_file("hemicnn.json", glint::fuzz::bytes(data, size));
  glint::fuzz::parse_or_reject([&] { glint::reflectance::HemiCnn::load(path); });
  return 0;
}
