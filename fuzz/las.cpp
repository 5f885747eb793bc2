// LAS 1.2-1.4 files: the header, VLRs, Extra Bytes descriptions and EVLRs, every record as a
// point cloud, and the output layout `glint edges classify` derives from the input's.
#include "io/las.h"

#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path =
      glint::fuzz::write_scratch_file("input.las", glint::fuzz::bytes(data, size));
  glint::fuzz::parse_or_reject([&] { glint::io::read_las(path); });
  glint::fuzz::parse_or_reject([&] {
    const glint::io::LasReader reader(path);
    glint::io::LasBoundedFields fields;
    glint::io::las_header_with_bounded_fields(reader.header(), path, fields);
  });
  return 0;
}
