#include "render/sequence_writer.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <optional>

#include "core/error.h"
#include "core/interrupt.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "core/timer.h"
#include "io/atomic_file.h"
#include "io/image_io.h"
#include "io/json_report.h"
#include "io/trajectory.h"
#include "render/renderer.h"
#include "render/scene_json.h"
#include "render/sensor.h"

namespace glint::render {
namespace {

namespace fs = std::filesystem;

constexpr int kDepthScale = 1000;  // depth PNG units per metre

double median(std::vector<double> values) {
  if (values.empty()) return 0;
  const auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// An existing out_dir is replaced only when it is empty or a previous sequence.
void check_replaceable(const fs::path& out_dir) {
  if (!fs::exists(out_dir)) return;
  if (fs::is_directory(out_dir) && (fs::is_empty(out_dir) || fs::exists(out_dir / "scene.json")))
    return;
  throw Error(out_dir.string(), "", "exists and is not a glint sequence; not replacing it");
}

struct ImageJob {
  std::string path;
  ImageF image;
  io::PngDepth depth = io::PngDepth::eight;
};

ImageF segment_values(const Image<std::uint16_t>& segment) {
  ImageF values(segment.width(), segment.height(), 1);
  for (std::size_t i = 0; i < segment.pixel_count(); ++i)
    values.plane(0)[i] = segment.plane(0)[i] / 65535.0f;
  return values;
}

// Removes the staging folder unless the finished sequence was moved out of it.
class StagingFolder {
 public:
  explicit StagingFolder(fs::path path) : path_(std::move(path)) { fs::remove_all(path_); }
  ~StagingFolder() {
    std::error_code ignored;
    fs::remove_all(path_, ignored);
  }
  StagingFolder(const StagingFolder&) = delete;
  StagingFolder& operator=(const StagingFolder&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

}  // namespace

SequenceStats write_sequence(const Scene& scene, const std::string& out_dir,
                             const SequenceOptions& options) {
  const int trajectory_frames = static_cast<int>(scene.trajectory.size());
  const int first = options.first_frame;
  const int available = trajectory_frames - first;
  const int count = options.frame_count < 0 ? available : std::min(options.frame_count, available);
  if (first < 0 || count <= 0)
    throw Error(out_dir, "",
                fmt::format("no frames to render: first {} count {} of a {}-pose trajectory", first,
                            options.frame_count, trajectory_frames));
  check_replaceable(out_dir);
  Stopwatch total;
  const StagingFolder staging_folder(out_dir + fmt::format(".partial-{}", ::getpid()));
  const fs::path& staging = staging_folder.path();
  std::vector<std::string> folders = {"rgb", "depth"};
  if (options.ground_truth)
    folders.insert(folders.end(),
                   {"gt/depth", "gt/normal", "gt/segment", "gt/kd", "gt/ks", "gt/alpha"});
  std::error_code error;
  for (const std::string& folder : folders) {
    fs::create_directories(staging / folder, error);
    if (error)
      throw Error((staging / folder).string(), "", "cannot create folder: " + error.message());
  }

  const Renderer renderer(scene);
  const Intrinsics& k = scene.camera.intrinsics;
  io::write_json((staging / "intrinsics.json").string(), {{"width", k.width},
                                                          {"height", k.height},
                                                          {"fx", k.fx},
                                                          {"fy", k.fy},
                                                          {"cx", k.cx},
                                                          {"cy", k.cy},
                                                          {"depth_scale", kDepthScale}});

  std::vector<io::StampedPose> groundtruth;
  std::string associations;
  std::vector<double> render_ms, frame_ms;
  std::optional<ProgressBar> progress;
  if (options.progress) progress.emplace("render", static_cast<std::size_t>(count));
  for (int frame = first; frame < first + count; ++frame) {
    throw_if_interrupted();  // also without a progress bar
    Stopwatch frame_watch;
    const Pose& pose = scene.trajectory[frame];
    const FrameBuffers buffers = renderer.render(pose, frame);
    render_ms.push_back(frame_watch.elapsed_ms());
    const std::string name = fmt::format("{:06d}", frame);
    std::vector<ImageJob> jobs;
    jobs.push_back(
        {"rgb/" + name + ".png", expose_colour(buffers.radiance, scene.camera, scene.seed, frame)});
    jobs.push_back({"depth/" + name + ".png",
                    depth_png_values(measure_depth(buffers.depth, scene.camera, scene.seed, frame)),
                    io::PngDepth::sixteen});
    if (options.ground_truth) {
      jobs.push_back({"gt/depth/" + name + ".exr", buffers.depth});
      jobs.push_back({"gt/normal/" + name + ".exr", buffers.normal});
      jobs.push_back(
          {"gt/segment/" + name + ".png", segment_values(buffers.segment), io::PngDepth::sixteen});
      jobs.push_back({"gt/kd/" + name + ".exr", buffers.kd});
      jobs.push_back({"gt/ks/" + name + ".exr", buffers.ks});
      jobs.push_back({"gt/alpha/" + name + ".exr", buffers.alpha});
    }
    parallel_for(jobs.size(), [&](std::size_t j) {
      io::write_image((staging / jobs[j].path).string(), jobs[j].image, jobs[j].depth);
    });
    const double timestamp = frame / scene.frames_per_second;
    associations +=
        fmt::format("{:.6f} rgb/{}.png {:.6f} depth/{}.png\n", timestamp, name, timestamp, name);
    groundtruth.push_back({timestamp, pose});
    frame_ms.push_back(frame_watch.elapsed_ms());
    if (progress) progress->advance();
  }
  if (progress) progress->finish();

  io::AtomicFile associations_file((staging / "associations.txt").string(), false);
  associations_file.stream() << associations;
  associations_file.commit();
  io::write_tum_trajectory((staging / "groundtruth.txt").string(), groundtruth);
  write_scene_json((staging / "scene.json").string(), scene);

  throw_if_interrupted();
  fs::remove_all(out_dir, error);
  if (!error) fs::rename(staging, out_dir, error);
  if (error)
    throw Error(out_dir, "", "cannot move the finished sequence into place: " + error.message());
  return {count, total.elapsed_s(), median(render_ms), median(frame_ms)};
}

}  // namespace glint::render
