// PLY point clouds and meshes (ascii, binary little and big endian): read_ply and
// read_ply_mesh, which also reads the faces.
#include "io/ply.h"

#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path =
      glint::fuzz::write_scratch_file("input.ply", glint::fuzz::bytes(data, size));
  glint::fuzz::parse_or_reject([&] { glint::io::read_ply(path); });
  glint::fuzz::parse_or_reject([&] { glint::io::read_ply_mesh(path); });
  return 0;
}
