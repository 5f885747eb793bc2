// PCD point clouds (ascii and binary DATA).
#include "io/pcd.h"

#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path =
      glint::fuzz::write_scratch_file("input.pcd", glint::fuzz::bytes(data, size));
  glint::fuzz::parse_or_reject([&] { glint::io::read_pcd(path); });
  return 0;
}
