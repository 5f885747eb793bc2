// lights.json (reflectance/light_estimation.h): estimated point lights and their support.
#include "fuzz_support.h"
#include "reflectance/light_estimation.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path =
      glint::fuzz::write_scratch_file("lights.json", glint::fuzz::bytes(data, size));
  glint::fuzz::parse_or_reject([&] { glint::reflectance::read_lights_json(path); });
  return 0;
}
