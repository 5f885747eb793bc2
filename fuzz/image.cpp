// Raster images through glint's decode path (io/image_io.h read_image -> io/image_decode.h):
// the format is sniffed from the content, so one target covers PNG, EXR, Radiance HDR, JPEG and
// the other codecs OpenCV was built with.
#include "fuzz_support.h"
#include "io/image_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path =
      glint::fuzz::write_scratch_file("input.png", glint::fuzz::bytes(data, size));
  glint::fuzz::parse_or_reject([&] { glint::io::read_image(path); });
  return 0;
}
