#include "reflectance/reconstruction_outputs.h"

#include <unistd.h>

#include <filesystem>
#include <map>

#include "core/error.h"
#include "core/interrupt.h"
#include "core/parallel.h"
#include "core/progress.h"
#include "fusion/depth_maps.h"
#include "fusion/marching_cubes.h"
#include "fusion/raycast.h"
#include "io/json_report.h"

namespace glint::reflectance {
namespace {

namespace fs = std::filesystem;

nlohmann::json ward_json(const render::WardMaterial& m) {
  return {{"kd", io::vector_json(m.kd)}, {"ks", io::vector_json(m.ks)}, {"alpha", m.alpha}};
}

}  // namespace

LightEstimate load_lights(const std::string& source) {
  if (!fs::is_directory(source)) return read_lights_json(source);
  const io::RgbdSequence capture = io::open_rgbd_sequence(source);
  ProgressBar progress("lights", capture.frames.size());
  LightEstimate estimate = estimate_lights(capture, {}, [&] { progress.advance(); });
  progress.finish();
  if (estimate.lights.empty()) throw Error(source, "", "no light found in the capture sequence");
  return estimate;
}

void render_model(const ReflectancePipeline& pipeline, const Intrinsics& intrinsics,
                  const Pose& pose, float normal_radius_m, StageTimings& timings,
                  MaterialMaps& maps, const ImageF* fused_depth) {
  Stopwatch watch;
  fusion::SurfaceView view = fusion::raycast(
      pipeline.geometry(), intrinsics, pose,
      {.normals = fusion::RaycastNormals::from_gradient, .depth_hint = fused_depth});
  timings.add("raycast", watch.elapsed_ms());
  if (normal_radius_m > 0) {
    watch.restart();
    view.normals = fusion::smooth_normals(view.points_m, view.normals, view.depth_m, intrinsics,
                                          normal_radius_m);
    timings.add("smooth_normals", watch.elapsed_ms());
  }
  watch.restart();
  render_material_maps(view, pose, pipeline.observations(), pipeline.materials(), pipeline.lights(),
                       pipeline.exposure(), pipeline.albedo_blend(), maps,
                       &pipeline.light_transport(), &pipeline.geometry());
  timings.add("shade", watch.elapsed_ms());
}

fusion::TriangleMesh material_mesh(const ReflectancePipeline& pipeline) {
  fusion::TriangleMesh mesh = fusion::extract_mesh(pipeline.geometry());
  const std::size_t n = mesh.vertices.size();
  std::array<std::vector<float>, 9> values;  // kd rgb, ks rgb, alpha, segment, observations
  for (auto& v : values) v.assign(n, 0.0f);
  mesh.colours.assign(n, Eigen::Vector3f::Zero());
  // Chunks of consecutive vertices (marching cubes emits them block by block), so that each
  // lookup mostly finds its neighbourhood kept from the vertex before.
  parallel_for_chunks(n, 1024, [&](std::size_t begin, std::size_t end) {
    const ObservationGrid& grid = pipeline.observations();
    MaterialLookup lookup(grid, pipeline.materials(), pipeline.albedo_blend());
    ObservationGrid::BlockCache blocks;
    for (std::size_t i = begin; i < end; ++i) {
      const int voxel = grid.find(mesh.vertices[i], &blocks);
      values[8][i] = voxel >= 0 ? float(grid.observation_count(voxel)) : 0.0f;
      PointMaterial material;
      const bool with_material = lookup(mesh.vertices[i], material);
      values[7][i] = float(material.segment);
      if (!with_material) continue;
      mesh.colours[i] = material.refined.kd;
      for (int c = 0; c < 3; ++c) {
        values[c][i] = material.refined.kd[c];
        values[3 + c][i] = material.fused.ks[c];
      }
      values[6][i] = material.fused.alpha;
    }
  });
  const std::array<const char*, 9> names{"kd_r", "kd_g",  "kd_b",           "ks_r",        "ks_g",
                                         "ks_b", "alpha", "scalar_segment", "observations"};
  for (int k = 0; k < 9; ++k) mesh.vertex_properties.emplace_back(names[k], std::move(values[k]));
  mesh.comments = {
      "glint reconstruct; red green blue: refined diffuse albedo kd, 8-bit sRGB",
      "kd_*: refined diffuse albedo, ks_*: specular albedo, alpha: Ward roughness (linear)",
      "scalar_segment: segment id (0 = none); vertices without a material have zeros",
      "observations: stored observations of the vertex's observation voxel (0-30)"};
  return mesh;
}

void write_material_mesh(const std::string& path, const ReflectancePipeline& pipeline) {
  fusion::write_mesh_ply(path, material_mesh(pipeline));
}

MaterialCoverage material_coverage(const ReflectancePipeline& pipeline, int min_voxels) {
  const SegmentMap& segments = pipeline.segments();
  MaterialCoverage coverage;
  for (int id = 1; id <= segments.max_segment_id(); ++id) {
    if (segments.resolve(id) != id || segments.reservoir_size(id) < min_voxels) continue;
    ++coverage.segments;
    if (!pipeline.materials().material(id)) ++coverage.without_material;
  }
  return coverage;
}

nlohmann::json materials_json(const ReflectancePipeline& pipeline) {
  const ObservationGrid& grid = pipeline.observations();
  // Per segment, the sum of the refined kd over all its voxels with one and over the reliable
  // ones; the mean is over the reliable ones where the segment has any.
  struct Sum {
    Eigen::Vector3d kd = Eigen::Vector3d::Zero();
    int voxels = 0;
    void add(const Eigen::Vector3f& value) {
      kd += value.cast<double>();
      ++voxels;
    }
  };
  struct RefinedSums {
    Sum all, reliable;
  };
  std::map<int, RefinedSums> refined;
  std::map<int, int> voxels;
  for (int v = 0; v < int(grid.voxel_count()); ++v) {
    const int segment = grid.segment(v);
    if (segment <= 0) continue;
    ++voxels[segment];
    if (!grid.has_refined_kd(v)) continue;
    RefinedSums& sums = refined[segment];
    sums.all.add(grid.refined_kd(v));
    if (grid.refined_kd_reliable(v)) sums.reliable.add(grid.refined_kd(v));
  }
  nlohmann::json segments = nlohmann::json::array();
  for (const auto& [id, material] : pipeline.materials().materials()) {
    if (voxels[id] == 0) continue;  // merged into another segment
    nlohmann::json entry = ward_json(material.ward);
    entry["id"] = id;
    entry["latest"] = ward_json(material.latest);
    entry["estimates"] = material.estimates;
    entry["lobe_fitted"] = material.fitted;
    entry["last_frame"] = material.last_frame;
    entry["voxels"] = voxels[id];
    if (const auto found = refined.find(id); found != refined.end()) {
      const RefinedSums& sums = found->second;
      const Sum& sum = sums.reliable.voxels > 0 ? sums.reliable : sums.all;
      entry["kd_refined_mean"] = io::vector_json((sum.kd / sum.voxels).cast<float>());
    }
    if (pipeline.light_transport().params().unseen)
      entry["unseen_irradiance"] = io::vector_json(pipeline.light_transport().unseen(id));
    segments.push_back(entry);
  }
  return {{"segments", segments},
          {"exposure", pipeline.exposure()},
          {"observation_voxel_m", grid.params().voxel_size_m}};
}

void write_materials_json(const std::string& path, const ReflectancePipeline& pipeline) {
  io::write_json(path, materials_json(pipeline));
}

void write_reconstruction(const std::string& folder, const ReflectancePipeline& pipeline,
                          const LightEstimate& lights) {
  write_material_mesh((fs::path(folder) / "mesh.ply").string(), pipeline);
  write_materials_json((fs::path(folder) / "materials.json").string(), pipeline);
  write_lights_json((fs::path(folder) / "lights.json").string(), lights);
}

ReconstructionFolder::ReconstructionFolder(std::string output) : output_(std::move(output)) {
  if (fs::exists(output_) &&
      !(fs::is_directory(output_) &&
        (fs::is_empty(output_) || fs::exists(fs::path(output_) / "materials.json"))))
    throw Error(output_, "", "exists and is not a glint reconstruction; not replacing it");
  partial_ = output_ + ".partial-" + std::to_string(::getpid());
  fs::remove_all(partial_);
  fs::create_directories(partial_);
}

ReconstructionFolder::~ReconstructionFolder() {
  std::error_code ignored;
  if (!committed_) fs::remove_all(partial_, ignored);
}

void ReconstructionFolder::commit() {
  throw_if_interrupted();
  fs::remove_all(output_);
  fs::rename(partial_, output_);
  committed_ = true;
}

}  // namespace glint::reflectance
