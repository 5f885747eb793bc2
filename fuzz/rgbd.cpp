// RGB-D sequence folders (io/rgbd_sequence.h): the index files of the glint, TUM, 7-Scenes and
// Redwood layouts (intrinsics, associations, file lists, TUM trajectories, 4x4 pose files,
// trajectory.log). An input is the layout's name on its first line, then the index files'
// contents separated by lines holding "====", in the order of kLayouts' file names; an empty
// section leaves that file out. The images come from the test fixture of the same layout, so
// the sequence opens and its first frame is decoded against the fuzzed intrinsics.
#include <filesystem>
#include <functional>

#include "fuzz_support.h"
#include "io/rgbd_sequence.h"

namespace {

struct Layout {
  std::string_view name;
  std::vector<std::string> files;
  std::function<glint::io::RgbdSequence(const std::string&)> open;
};

const std::vector<Layout>& layouts() {
  static const std::vector<Layout> kLayouts = {
      {"glint",
       {"intrinsics.json", "associations.txt", "groundtruth.txt"},
       glint::io::open_glint_sequence},
      {"tum",
       {"rgb.txt", "depth.txt", "groundtruth.txt", "intrinsics.json"},
       glint::io::open_tum_sequence},
      {"7scenes",
       {"camera-intrinsics.txt", "rgbd-frames/frame-000150.pose.txt",
        "rgbd-frames/frame-000151.pose.txt"},
       glint::io::open_7scenes_sequence},
      {"redwood", {"camera_primesense.json", "trajectory.log"}, glint::io::open_redwood_sequence},
  };
  return kLayouts;
}

// scratch/<layout>: a copy of the fixture folder, made once.
std::string fixture_copy(std::string_view layout) {
  const std::string folder = glint::fuzz::scratch_folder() + "/" + std::string(layout);
  if (!std::filesystem::exists(folder)) {
    std::filesystem::copy(std::string(GLINT_FUZZ_RGBD_FIXTURES) + "/" + std::string(layout), folder,
                          std::filesystem::copy_options::recursive);
  }
  return folder;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view input = glint::fuzz::bytes(data, size);
  const std::size_t end_of_name = input.find('\n');
  if (end_of_name == std::string_view::npos) return 0;
  const std::string_view name = input.substr(0, end_of_name);
  input.remove_prefix(end_of_name + 1);
  for (const Layout& layout : layouts()) {
    if (layout.name != name) continue;
    const std::string folder = fixture_copy(layout.name);
    const auto sections = glint::fuzz::split_sections(input, layout.files.size());
    for (std::size_t i = 0; i < layout.files.size(); ++i) {
      const std::string relative = std::string(layout.name) + "/" + layout.files[i];
      if (sections[i].empty()) {
        std::filesystem::remove(glint::fuzz::scratch_folder() + "/" + relative);
      } else {
        glint::fuzz::write_scratch_file(relative, sections[i]);
      }
    }
    glint::fuzz::parse_or_reject([&] {
      const glint::io::RgbdSequence sequence = layout.open(folder);
      if (!sequence.frames.empty()) glint::io::read_rgbd_frame(sequence, 0);
    });
  }
  return 0;
}
