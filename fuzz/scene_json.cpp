// scene.json (render/scene_json.h): camera path, objects, materials, lights, environment.
#include "render/scene_json.h"

#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path =
      glint::fuzz::write_scratch_file("scene.json", glint::fuzz::bytes(data, size));
  glint::fuzz::parse_or_reject([&] { glint::render::read_scene_json(path); });
  return 0;
}
