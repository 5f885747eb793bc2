#include "gltf/scene_export.h"

#include <meshoptimizer.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <opencv2/imgcodecs.hpp>

#include "core/error.h"
#include "core/log.h"
#include "core/parallel.h"
#include "core/timer.h"
#include "fusion/triangle_mesh.h"
#include "geometry/kdtree.h"
#include "gltf/albedo_denoising.h"
#include "gltf/albedo_truth.h"
#include "gltf/material_conversion.h"
#include "gltf/texture_atlas.h"
#include "io/json_report.h"
#include "io/ply.h"

namespace glint::gltf {
namespace {

namespace fs = std::filesystem;

constexpr int kLinear = 9729, kClampToEdge = 33071;
// The atlas samples the full-resolution mesh: the refined kd of its nearest vertices.
constexpr int kAtlasNeighbours = 8;
// The atlas's errors against the truth split texels at half a voxel's observation capacity
// (m = 30): at least 15 observations is "well observed".
constexpr float kWellObserved = 15;

const std::vector<float>& float_column(const PointCloud& cloud, const char* name,
                                       const std::string& path) {
  const std::vector<float>* column = cloud.get<float>(name);
  if (!column) throw Error(path, name, "missing float vertex property (not a glint mesh.ply)");
  return *column;
}

// meshoptimizer's simplification to `budget` triangles: the attribute-blind edge collapse within
// 1 % of the mesh's extent, then, if that stops above the budget, the sloppy clustering.
std::vector<Eigen::Vector3i> simplify(const Reconstruction& scene, std::size_t budget,
                                      float& error_m) {
  error_m = 0;
  if (budget == 0 || scene.triangles.size() <= budget) return scene.triangles;
  const float* positions = scene.vertices.front().data();
  const std::size_t n = scene.vertices.size(), stride = sizeof(Eigen::Vector3f);
  std::vector<std::uint32_t> indices(3 * scene.triangles.size());
  for (std::size_t t = 0; t < scene.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) indices[3 * t + k] = std::uint32_t(scene.triangles[t][k]);
  std::vector<std::uint32_t> out(indices.size());
  float relative = 0;
  std::size_t count = meshopt_simplify(out.data(), indices.data(), indices.size(), positions, n,
                                       stride, 3 * budget, 1e-2f, 0, &relative);
  out.resize(count);
  if (count > 3 * budget) {
    std::vector<std::uint32_t> sloppy(count);
    float sloppy_error = 0;
    sloppy.resize(meshopt_simplifySloppy(sloppy.data(), out.data(), out.size(), positions, n,
                                         stride, 3 * budget, 1.0f, &sloppy_error));
    out = std::move(sloppy);
    relative = std::max(relative, sloppy_error);
  }
  error_m = relative * meshopt_simplifyScale(positions, n, stride);
  std::vector<Eigen::Vector3i> triangles(out.size() / 3);
  for (std::size_t t = 0; t < triangles.size(); ++t)
    triangles[t] = {int(out[3 * t]), int(out[3 * t + 1]), int(out[3 * t + 2])};
  return triangles;
}

// A triangle's segment: the one two or three of its vertices share, else its first vertex's.
int triangle_segment(const std::vector<int>& segment, const Eigen::Vector3i& f) {
  if (segment[f[1]] == segment[f[2]]) return segment[f[1]];
  return segment[f[0]];
}

std::vector<Eigen::Vector3f> vertex_normals(const std::vector<Eigen::Vector3f>& vertices,
                                            const std::vector<Eigen::Vector3i>& triangles) {
  std::vector<Eigen::Vector3f> normals(vertices.size(), Eigen::Vector3f::Zero());
  for (const Eigen::Vector3i& f : triangles) {
    // Area-weighted: the cross product's length is twice the area.
    const Eigen::Vector3f n =
        (vertices[f[1]] - vertices[f[0]]).cross(vertices[f[2]] - vertices[f[0]]);
    for (int k = 0; k < 3; ++k) normals[f[k]] += n;
  }
  for (Eigen::Vector3f& n : normals) {
    const float length = n.norm();
    n = length > 0 ? Eigen::Vector3f(n / length) : Eigen::Vector3f::UnitY();
  }
  return normals;
}

// The kd at a surface point: inverse-distance mean of the nearest full-resolution vertices of
// the triangle's segment that carry a material (each is the trilinear refined kd at that
// vertex, reflectance/material_maps.h); of any vertex with one when none of the segment is near.
// Likewise the observation count, over the nearest vertices of any segment.
class AlbedoSampler {
 public:
  explicit AlbedoSampler(const Reconstruction& scene) : scene_(scene) {
    cloud_.reserve(scene.vertices.size());
    for (const Eigen::Vector3f& v : scene.vertices) cloud_.push_back(v.x(), v.y(), v.z());
    tree_ = std::make_unique<geometry::KdTree>(cloud_);
  }
  Eigen::Vector3f kd(const Eigen::Vector3f& p, int segment) const {
    std::uint32_t index[kAtlasNeighbours];
    float d2[kAtlasNeighbours];
    const int found = tree_->knn(p.data(), kAtlasNeighbours, index, d2);
    for (const bool same_segment : {true, false}) {
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      float weight = 0;
      for (int k = 0; k < found; ++k) {
        const std::uint32_t v = index[k];
        if (scene_.segment[v] <= 0 || scene_.kd[v].isZero()) continue;
        if (same_segment && scene_.segment[v] != segment) continue;
        const float w = inverse_distance(d2[k]);
        sum += w * scene_.kd[v];
        weight += w;
      }
      if (weight > 0) return sum / weight;
    }
    return Eigen::Vector3f::Zero();
  }
  float observations(const Eigen::Vector3f& p) const {
    std::uint32_t index[kAtlasNeighbours];
    float d2[kAtlasNeighbours];
    const int found = tree_->knn(p.data(), kAtlasNeighbours, index, d2);
    float sum = 0, weight = 0;
    for (int k = 0; k < found; ++k) {
      sum += inverse_distance(d2[k]) * scene_.observations[index[k]];
      weight += inverse_distance(d2[k]);
    }
    return weight > 0 ? sum / weight : 0.0f;
  }

 private:
  static float inverse_distance(float d2) { return 1.0f / (std::sqrt(d2) + 1e-4f); }

  const Reconstruction& scene_;
  PointCloud cloud_;
  std::unique_ptr<geometry::KdTree> tree_;
};

// --denoise-albedo: `image` (the atlas baked from `kd` over `layout`) is replaced by its
// denoised bake. --albedo-truth: the errors of the atlas (and of the denoised one) against the
// truth, split by observation count. Both go to stats.albedo.
void denoise_and_evaluate(const Reconstruction& scene,
                          const std::vector<Eigen::Vector3i>& triangles,
                          const std::vector<int>& segment_of, const ExportParams& params,
                          const AlbedoSampler& sampler, const SurfaceSampler& kd,
                          AtlasLayout& layout, const std::vector<std::uint8_t>& baked,
                          ImageF& image, ExportStats& stats) {
  if (scene.observations.empty())
    throw Error("mesh.ply", "observations",
                "missing vertex property (a reconstruction from an older glint); run glint "
                "reconstruct again to denoise or evaluate the albedo atlas");
  const AtlasParams atlas{.size = params.texture_size};
  const SurfaceSampler observations = [&](const Eigen::Vector3f& p, int) {
    return Eigen::Vector3f(sampler.observations(p), 0, 0);
  };
  const ImageF baked_kd = image;
  if (params.denoise_albedo) {
    const AlbedoCorrection correction(
        scene.vertices, triangles, segment_of, kd, observations,
        {.settings = params.denoise, .voxel_m = scene.observation_voxel_m});
    image = bake_atlas(
        layout, scene.vertices,
        [&](const Eigen::Vector3f& p, int t) {
          return Eigen::Vector3f((kd(p, t) + correction(p, t)).cwiseMax(0.0f).cwiseMin(1.0f));
        },
        atlas);
    stats.albedo["denoising"] = correction.stats().to_json();
  }
  if (params.albedo_truth.empty()) return;
  const AlbedoTruth truth(params.albedo_truth);
  const ImageF true_kd = bake_atlas(
      layout, scene.vertices, [&](const Eigen::Vector3f& p, int) { return truth(p); }, atlas);
  // The split by observation count is needed only here: the denoiser bakes its own counts.
  const ImageF counts = bake_atlas(layout, scene.vertices, observations, atlas);
  nlohmann::json& report = stats.albedo["truth"];
  report["sequence"] = params.albedo_truth;
  report["views"] = truth.views();
  report["atlas"] = albedo_errors(baked_kd, true_kd, counts, baked, kWellObserved);
  if (params.denoise_albedo)
    report["denoised"] = albedo_errors(image, true_kd, counts, baked, kWellObserved);
}

std::vector<std::uint8_t> encode_srgb_png(const ImageF& image) {
  cv::Mat bgr(image.height(), image.width(), CV_8UC3);
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x)
      for (int c = 0; c < 3; ++c)
        bgr.at<cv::Vec3b>(y, x)[2 - c] = fusion::linear_to_srgb8(image.at(x, y, c));
  std::vector<std::uint8_t> png;
  if (!cv::imencode(".png", bgr, png)) throw Error("texture atlas", "", "PNG encoding failed");
  return png;
}

Eigen::Vector3f json_vector(const nlohmann::json& value) {
  return {value.at(0).get<float>(), value.at(1).get<float>(), value.at(2).get<float>()};
}

nlohmann::json rgb_json(const Eigen::Vector3f& v) { return {v.x(), v.y(), v.z()}; }

// The glTF material of one segment: Ward's values from materials.json when it has them, else
// a rough, non-specular one.
nlohmann::json segment_material(int segment, const nlohmann::json* ward, bool textured) {
  Eigen::Vector3f kd(0.5f, 0.5f, 0.5f), ks = Eigen::Vector3f::Zero();
  float alpha = 1;
  nlohmann::json extras = {{"segment", segment}};
  if (ward) {
    try {
      kd = json_vector(ward->at("kd"));
      ks = json_vector(ward->at("ks"));
      alpha = ward->at("alpha").get<float>();
      if (ward->contains("kd_refined_mean")) kd = json_vector(ward->at("kd_refined_mean"));
    } catch (const nlohmann::json::exception& e) {
      throw Error("materials.json", "segment " + std::to_string(segment), e.what());
    }
    extras["ward"] = {{"kd", ward->at("kd")}, {"ks", ward->at("ks")}, {"alpha", ward->at("alpha")}};
    for (const char* key : {"kd_refined_mean", "estimates", "voxels", "lobe_fitted"})
      if (ward->contains(key)) extras[key] = ward->at(key);
  }
  nlohmann::json pbr = {{"metallicFactor", 0.0},
                        {"roughnessFactor", ward ? ward_alpha_to_roughness(alpha) : 1.0f}};
  // With the atlas the texture is kd; without it COLOR_0 is, and the factor stays 1.
  pbr["baseColorFactor"] = {1.0, 1.0, 1.0, 1.0};
  if (textured) pbr["baseColorTexture"] = {{"index", 0}};
  nlohmann::json material = {
      {"name", segment > 0 ? "segment_" + std::to_string(segment) : std::string("unsegmented")},
      {"pbrMetallicRoughness", pbr},
      {"extras", extras}};
  if (ward)
    material["extensions"]["KHR_materials_specular"] = {
        {"specularFactor", 1.0}, {"specularColorFactor", rgb_json(specular_color_factor(ks))}};
  else
    material["extensions"]["KHR_materials_specular"] = {{"specularFactor", 0.0}};
  return material;
}

}  // namespace

UpAxis parse_up_axis(const std::string& text, const std::string& option) {
  static const std::map<std::string, UpAxis> kNames{{"+x", UpAxis::pos_x}, {"-x", UpAxis::neg_x},
                                                    {"+y", UpAxis::pos_y}, {"-y", UpAxis::neg_y},
                                                    {"+z", UpAxis::pos_z}, {"-z", UpAxis::neg_z}};
  const auto found = kNames.find(text);
  if (found == kNames.end())
    throw Error(option, text, "not an axis: give one of +x, -x, +y, -y, +z, -z");
  return found->second;
}

const char* up_axis_name(UpAxis up) {
  static const char* const kNames[] = {"+x", "-x", "+y", "-y", "+z", "-z"};
  return kNames[int(up)];
}

Eigen::Quaternionf world_to_gltf(UpAxis up) {
  static const Eigen::Vector3f kAxes[] = {Eigen::Vector3f::UnitX(), -Eigen::Vector3f::UnitX(),
                                          Eigen::Vector3f::UnitY(), -Eigen::Vector3f::UnitY(),
                                          Eigen::Vector3f::UnitZ(), -Eigen::Vector3f::UnitZ()};
  // -y -> +y: half a turn about x (not the ambiguous shortest arc), so z flips too.
  if (up == UpAxis::neg_y) return Eigen::Quaternionf(0, 1, 0, 0);
  return Eigen::Quaternionf::FromTwoVectors(kAxes[int(up)], Eigen::Vector3f::UnitY());
}

Reconstruction read_reconstruction(const std::string& folder) {
  if (!fs::is_directory(folder))
    throw Error(folder, "", "is not a folder (give a glint reconstruct output)");
  const std::string mesh_path = (fs::path(folder) / "mesh.ply").string();
  const std::string materials_path = (fs::path(folder) / "materials.json").string();
  const std::string lights_path = (fs::path(folder) / "lights.json").string();
  for (const std::string& path : {mesh_path, materials_path, lights_path})
    if (!fs::exists(path)) throw Error(path, "", "missing: not a glint reconstruction");
  Reconstruction scene;
  io::PlyMesh mesh = io::read_ply_mesh(mesh_path);
  const PointCloud& v = mesh.vertices;
  const std::vector<float>& r = float_column(v, "kd_r", mesh_path);
  const std::vector<float>& g = float_column(v, "kd_g", mesh_path);
  const std::vector<float>& b = float_column(v, "kd_b", mesh_path);
  const std::vector<float>& segment = float_column(v, "scalar_segment", mesh_path);
  if (const std::vector<float>* observations = v.get<float>("observations"))
    scene.observations = *observations;
  scene.vertices.resize(v.size());
  scene.kd.resize(v.size());
  scene.segment.resize(v.size());
  for (std::size_t i = 0; i < v.size(); ++i) {
    scene.vertices[i] = v.point(i);
    scene.kd[i] = {r[i], g[i], b[i]};
    scene.segment[i] = int(segment[i]);
  }
  scene.triangles = std::move(mesh.triangles);
  scene.materials = io::read_json(materials_path);
  if (scene.materials.contains("observation_voxel_m")) {
    const nlohmann::json& size = scene.materials.at("observation_voxel_m");
    if (!size.is_number() || !(size.get<float>() > 0))
      throw Error(materials_path, "observation_voxel_m", "must be a positive length in metres");
    scene.observation_voxel_m = size.get<float>();
  }
  scene.lights = reflectance::read_lights_json(lights_path);
  return scene;
}

nlohmann::json ExportStats::counts_json() const {
  return {{"input_triangles", input_triangles},
          {"triangles", triangles},
          {"vertices", vertices},
          {"simplification_error_m", simplification_error_m},
          {"charts", charts},
          {"texels_per_metre", texels_per_metre},
          {"overlapping_texels", overlapping_texels},
          {"materials", materials},
          {"lights", lights}};
}

nlohmann::json ExportStats::to_json() const {
  nlohmann::json json = counts_json();
  json["seconds"] = {
      {"simplify", simplify_s}, {"layout", layout_s}, {"bake", bake_s}, {"png", png_s}};
  if (!albedo.is_null()) json["albedo"] = albedo;
  return json;
}

GlbBuilder build_scene_glb(const Reconstruction& scene, const ExportParams& params,
                           ExportStats* stats_out) {
  if (scene.triangles.empty()) throw Error("reconstruction", "mesh", "has no triangles");
  ExportStats stats;
  stats.input_triangles = scene.triangles.size();
  Stopwatch watch;
  const std::vector<Eigen::Vector3i> triangles =
      simplify(scene, params.mesh_triangles, stats.simplification_error_m);
  stats.simplify_s = watch.elapsed_s();
  stats.triangles = triangles.size();
  std::vector<int> segment_of(triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t)
    segment_of[t] = triangle_segment(scene.segment, triangles[t]);
  const std::vector<Eigen::Vector3f> normals = vertex_normals(scene.vertices, triangles);

  GlbBuilder glb;
  nlohmann::json& doc = glb.document();
  const bool textured = params.texture_size > 0;
  // Output vertices: with the atlas one per (mesh vertex, chart), else the mesh's.
  AtlasLayout layout;
  if (textured) {
    AtlasParams atlas{.size = params.texture_size};
    watch.restart();
    layout = layout_atlas(scene.vertices, triangles, segment_of, atlas);
    stats.layout_s = watch.elapsed_s();
    watch.restart();
    const AlbedoSampler sampler(scene);
    const SurfaceSampler kd = [&](const Eigen::Vector3f& p, int t) {
      return sampler.kd(p, segment_of[t]);
    };
    std::vector<std::uint8_t> baked;
    ImageF image = bake_atlas(layout, scene.vertices, kd, atlas, &baked);
    stats.bake_s = watch.elapsed_s();
    if (params.denoise_albedo || !params.albedo_truth.empty())
      denoise_and_evaluate(scene, triangles, segment_of, params, sampler, kd, layout, baked, image,
                           stats);
    stats.charts = layout.charts;
    stats.texels_per_metre = layout.texels_per_metre;
    stats.overlapping_texels = layout.overlapping_texels;
    watch.restart();
    const int view = glb.add_buffer_view(encode_srgb_png(image));
    stats.png_s = watch.elapsed_s();
    doc["images"] = {{{"bufferView", view}, {"mimeType", "image/png"}, {"name", "kd_atlas"}}};
    doc["samplers"] = {{{"magFilter", kLinear},
                        {"minFilter", kLinear},
                        {"wrapS", kClampToEdge},
                        {"wrapT", kClampToEdge}}};
    doc["textures"] = {{{"sampler", 0}, {"source", 0}}};
  } else {
    layout.triangles = triangles;
  }
  const auto source = [&](int v) { return textured ? int(layout.source_vertex[v]) : v; };

  // Materials from materials.json by segment id.
  std::map<int, const nlohmann::json*> ward;
  if (scene.materials.contains("segments"))
    for (const nlohmann::json& entry : scene.materials.at("segments"))
      ward[entry.at("id").get<int>()] = &entry;
  std::map<int, std::vector<int>> segment_triangles;
  for (std::size_t t = 0; t < triangles.size(); ++t)
    segment_triangles[segment_of[t]].push_back(int(t));

  nlohmann::json primitives = nlohmann::json::array();
  std::vector<int> local;  // output vertex -> primitive vertex, -1 unused
  for (const auto& [segment, members] : segment_triangles) {
    const std::size_t outputs = textured ? layout.source_vertex.size() : scene.vertices.size();
    local.assign(outputs, -1);
    std::vector<std::uint32_t> indices;
    std::vector<float> position, normal, uv, albedo, segment_values;
    indices.reserve(3 * members.size());
    for (const int t : members)
      for (int k = 0; k < 3; ++k) {
        const int v = layout.triangles[t][k];
        if (local[v] < 0) {
          local[v] = int(position.size() / 3);
          const int s = source(v);
          position.insert(position.end(), scene.vertices[s].data(), scene.vertices[s].data() + 3);
          normal.insert(normal.end(), normals[s].data(), normals[s].data() + 3);
          albedo.insert(albedo.end(), scene.kd[s].data(), scene.kd[s].data() + 3);
          segment_values.push_back(float(segment));
          if (textured) uv.insert(uv.end(), layout.uv[v].data(), layout.uv[v].data() + 2);
        }
        indices.push_back(std::uint32_t(local[v]));
      }
    stats.vertices += position.size() / 3;
    nlohmann::json attributes = {{"POSITION", glb.add_float_accessor(position, 3, true)},
                                 {"NORMAL", glb.add_float_accessor(normal, 3)},
                                 {"_SEGMENT", glb.add_float_accessor(segment_values, 1)}};
    // glTF multiplies COLOR_0 into the base colour texture: with the atlas the per-vertex kd
    // goes to _ALBEDO, without it COLOR_0 is the base colour (docs/decisions.md).
    if (textured) {
      attributes["TEXCOORD_0"] = glb.add_float_accessor(uv, 2);
      attributes["_ALBEDO"] = glb.add_float_accessor(albedo, 3);
    } else {
      attributes["COLOR_0"] = glb.add_float_accessor(albedo, 3);
    }
    const auto found = ward.find(segment);
    doc["materials"].push_back(segment_material(
        segment, segment > 0 && found != ward.end() ? found->second : nullptr, textured));
    primitives.push_back({{"attributes", attributes},
                          {"indices", glb.add_index_accessor(indices)},
                          {"material", int(doc["materials"].size()) - 1},
                          {"mode", 4}});
  }
  stats.materials = int(doc["materials"].size());
  doc["meshes"] = {{{"name", "reconstruction"}, {"primitives", primitives}}};

  // Nodes: 0 the root (world axes), 1 the mesh, 2... the lights, all children of the root.
  const Eigen::Quaternionf rotation = world_to_gltf(params.up);
  nlohmann::json root = {
      {"name", "glint_world"}, {"extras", {{"up", up_axis_name(params.up)}}}, {"children", {1}}};
  if (!rotation.coeffs().isApprox(Eigen::Quaternionf::Identity().coeffs()))
    root["rotation"] = {rotation.x(), rotation.y(), rotation.z(), rotation.w()};
  doc["nodes"] = {root, {{"name", "reconstruction"}, {"mesh", 0}}};
  nlohmann::json lights = nlohmann::json::array();
  for (std::size_t i = 0; i < scene.lights.lights.size(); ++i) {
    const render::PointLight& light = scene.lights.lights[i];
    const PunctualLight punctual = punctual_light(light.intensity);
    lights.push_back({{"name", "light_" + std::to_string(i)},
                      {"type", "point"},
                      {"color", rgb_json(punctual.color)},
                      {"intensity", punctual.intensity}});
    doc["nodes"][0]["children"].push_back(doc["nodes"].size());
    doc["nodes"].push_back(
        {{"name", "light_" + std::to_string(i)},
         {"translation", {light.position.x(), light.position.y(), light.position.z()}},
         {"extensions", {{"KHR_lights_punctual", {{"light", i}}}}},
         {"extras",
          {{"intensity", rgb_json(light.intensity)}, {"radius_m", light.proxy_radius_m}}}});
  }
  stats.lights = int(lights.size());
  doc["extensionsUsed"] = {"KHR_materials_specular"};
  if (!lights.empty()) {
    doc["extensionsUsed"].push_back("KHR_lights_punctual");
    doc["extensions"]["KHR_lights_punctual"]["lights"] = lights;
  }
  nlohmann::json extras = {{"up", up_axis_name(params.up)},
                           {"exposure", scene.materials.value("exposure", 1.0)},
                           {"light_intensity_unit", "candela = glint intensity"},
                           {"export", stats.counts_json()}};
  doc["scenes"] = {{{"name", "glint"}, {"nodes", {0}}, {"extras", {{"glint", extras}}}}};
  doc["scene"] = 0;
  if (stats_out) *stats_out = stats;
  return glb;
}

ExportStats write_scene_glb(const Reconstruction& scene, const ExportParams& params,
                            const std::string& path) {
  ExportStats stats;
  build_scene_glb(scene, params, &stats).write(path);
  return stats;
}

}  // namespace glint::gltf
