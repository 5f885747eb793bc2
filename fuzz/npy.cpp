// NumPy .npy arrays, read as arrays (io/npy.h) and as images (io/image_io.h).
#include "io/npy.h"

#include "fuzz_support.h"
#include "io/image_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path =
      glint::fuzz::write_scratch_file("input.npy", glint::fuzz::bytes(data, size));
  glint::fuzz::parse_or_reject([&] { glint::io::read_npy(path); });
  glint::fuzz::parse_or_reject([&] { glint::io::read_image(path); });
  return 0;
}
