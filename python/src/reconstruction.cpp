// glint.Reconstruction: the online reflectance pipeline of `glint reconstruct` (paper 1), fed
// frame by frame from NumPy arrays.
#include <fmt/format.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <mutex>
#include <optional>

#include "bindings.h"
#include "core/error.h"
#include "core/resources.h"
#include "numpy_support.h"
#include "reflectance/albedo_refinement.h"
#include "reflectance/hemicnn.h"
#include "reflectance/reconstruction_outputs.h"
#include "reflectance/reflectance_pipeline.h"

namespace glint::python {
namespace {

Intrinsics intrinsics_from(const py::handle& object) {
  if (!py::isinstance<py::dict>(object))
    throw Error("intrinsics", "", "must be a dict with width, height, fx, fy, cx, cy");
  const auto d = py::reinterpret_borrow<py::dict>(object);
  Intrinsics k;
  for (const char* key : {"width", "height", "fx", "fy", "cx", "cy"})
    if (!d.contains(key)) throw Error("intrinsics", key, "missing");
  k.width = d["width"].cast<int>();
  k.height = d["height"].cast<int>();
  k.fx = d["fx"].cast<double>();
  k.fy = d["fy"].cast<double>();
  k.cx = d["cx"].cast<double>();
  k.cy = d["cy"].cast<double>();
  if (!k.valid()) throw Error("intrinsics", "", "width, height > 0 and fx, fy != 0 needed");
  return k;
}

// `lights`: a lights.json or light-capture folder path, or a list of dicts with position,
// intensity and optionally radius_m (lights.json's fields).
reflectance::LightEstimate lights_from(const py::handle& object) {
  if (py::isinstance<py::str>(object) || py::hasattr(object, "__fspath__"))
    return reflectance::load_lights(path_from(object));
  reflectance::LightEstimate estimate;
  estimate.capture = "(given to glint.Reconstruction)";
  if (!py::isinstance<py::list>(object) && !py::isinstance<py::tuple>(object))
    throw Error("lights", "", "must be a path or a list of dicts (position, intensity)");
  int index = 0;
  for (const py::handle item : object) {
    const std::string element = fmt::format("light {}", index++);
    if (!py::isinstance<py::dict>(item))
      throw Error("lights", element, "must be a dict with position and intensity");
    const auto d = py::reinterpret_borrow<py::dict>(item);
    if (!d.contains("position") || !d.contains("intensity"))
      throw Error("lights", element, "needs position and intensity");
    render::PointLight light;
    const auto position =
        matrix_from_array(d["position"], 1, 3, "lights: " + element + ": position");
    const auto intensity =
        matrix_from_array(d["intensity"], 1, 3, "lights: " + element + ": intensity");
    light.position = {position[0], position[1], position[2]};
    light.intensity = Eigen::Vector3d(intensity[0], intensity[1], intensity[2]).cast<float>();
    if (d.contains("radius_m")) light.proxy_radius_m = d["radius_m"].cast<double>();
    estimate.lights.push_back(light);
  }
  if (estimate.lights.empty()) throw Error("lights", "", "no light given");
  return estimate;
}

Pose pose_from(const py::handle& object, const std::string& name) {
  const std::vector<double> m = matrix_from_array(object, 4, 4, name);
  Eigen::Matrix4d matrix;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) matrix(r, c) = m[4 * r + c];
  Pose pose;
  pose.matrix() = matrix;
  return pose;
}

py::array pose_array(const Pose& pose) {
  std::vector<double> values(16);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) values[4 * r + c] = pose.matrix()(r, c);
  return array_from_vector(std::move(values), {4, 4});
}

py::object json_to_python(const nlohmann::json& value) {
  return py::module_::import("json").attr("loads")(value.dump());
}

// The keyword options, with the CLI's names ('_' for '-') and defaults.
reflectance::ReflectanceParams params_from(const py::dict& options, std::string& model,
                                           float& render_normal_radius) {
  reflectance::ReflectanceParams p;
  p.geometry.device = fusion::IntegrationDevice::automatic;  // the CLI's --device auto
  fusion::VolumeParams& volume = p.geometry.volume;
  for (const auto& option : options) {
    const std::string name = py::str(option.first);
    const auto positive = [&](double v) {
      if (!(v > 0)) throw Error(name, "", fmt::format("must be more than 0, got {}", v));
      return v;
    };
    set_option(name, option.second, [&](const py::handle& value) {
      if (name == "model") {
        if (!value.is_none()) model = path_from(value);
      } else if (name == "gt_poses") {
        p.geometry.use_ground_truth_poses = value.cast<bool>();
      } else if (name == "exposure") {
        p.exposure = float(positive(value.cast<double>()));
      } else if (name == "obs_voxel") {
        p.observations.voxel_size_m = float(positive(value.cast<double>()));
      } else if (name == "obs_voxels") {
        if (!value.is_none())
          p.observations.voxel_capacity = std::size_t(positive(value.cast<double>()));
      } else if (name == "obs_spacing") {
        p.observations.min_observation_spacing_deg = value.cast<float>();
      } else if (name == "obs_spacing_frames") {
        p.observations.spacing_max_frames = value.cast<int>();
      } else if (name == "voxel") {
        volume.voxel_size_m = positive(value.cast<double>());
      } else if (name == "trunc") {
        volume.truncation_m = positive(value.cast<double>());
      } else if (name == "trunc_per_depth") {
        volume.truncation_per_depth = value.cast<double>();
      } else if (name == "depth_max") {
        volume.depth_max_m = positive(value.cast<double>());
      } else if (name == "blocks") {
        volume.block_capacity = std::size_t(positive(value.cast<double>()));
      } else if (name == "far_every") {
        volume.far_fusion_every = value.cast<int>();
      } else if (name == "far_voxel_pixels") {
        volume.far_voxel_pixels = float(positive(value.cast<double>()));
      } else if (name == "track_model_halvings") {
        p.geometry.tracking.model_halvings = value.cast<int>();
      } else if (name == "device") {
        const std::string device = value.cast<std::string>();
        if (device != "cpu" && device != "cuda" && device != "auto")
          throw Error("device", device, "must be cpu, cuda or auto");
        p.geometry.device = device == "cpu"    ? fusion::IntegrationDevice::cpu
                            : device == "cuda" ? fusion::IntegrationDevice::cuda
                                               : fusion::IntegrationDevice::automatic;
      } else if (name == "segment_noise") {
        p.segmentation.convexity_noise_k = value.cast<float>();
      } else if (name == "albedo_every") {
        p.albedo_refresh_frames = int(positive(value.cast<int>()));
      } else if (name == "albedo_average") {
        p.albedo_average = reflectance::parse_albedo_average(value.cast<std::string>());
      } else if (name == "albedo_keep_clipped") {
        p.albedo_keep_clipped = value.cast<bool>();
      } else if (name == "albedo_min_cosine") {
        p.albedo_min_light_cosine = value.cast<float>();
      } else if (name == "albedo_max_indirect") {
        p.albedo_max_indirect_share = value.cast<float>();
      } else if (name == "albedo_shrinkage") {
        p.albedo_shrinkage = value.cast<bool>();
      } else if (name == "albedo_normal_error") {
        p.albedo_normal_error = value.cast<float>();
      } else if (name == "albedo_max_ratio") {
        p.albedo_max_ratio = value.cast<float>();
      } else if (name == "albedo_smoothing") {
        p.albedo_smoothing = value.cast<float>();
      } else if (name == "specular") {
        const std::string specular = value.cast<std::string>();
        if (specular != "hemicnn" && specular != "hemicnn+fit")
          throw Error("specular", specular, "must be hemicnn or hemicnn+fit");
        p.specular.fit_lobe = specular == "hemicnn+fit";
      } else if (name == "normals") {
        const std::string normals = value.cast<std::string>();
        if (normals != "gradient" && normals != "plane")
          throw Error("normals", normals, "must be gradient or plane");
        p.observations.normal_from_neighbours = normals == "plane";
      } else if (name == "shadows") {
        p.light_transport.shadows = value.cast<bool>();
      } else if (name == "shadow_test") {
        p.light_transport.shadow_test = value.cast<bool>();
      } else if (name == "shadow_test_sigmas") {
        p.light_transport.shadow_test_sigmas = value.cast<float>();
      } else if (name == "indirect") {
        p.light_transport.indirect = value.cast<bool>();
      } else if (name == "unseen_light") {
        p.light_transport.unseen = value.cast<bool>();
      } else if (name == "indirect_rays") {
        const int rays = value.cast<int>();
        if (rays < 1 || rays > 65535)
          throw Error(name, "", fmt::format("must be in [1, 65535], got {}", rays));
        p.light_transport.indirect_rays = rays;
      } else if (name == "indirect_rays_per_frame") {
        p.light_transport.indirect_rays_per_frame = int(positive(value.cast<int>()));
      } else if (name == "indirect_pooling") {
        p.light_transport.indirect_pooling = value.cast<bool>();
      } else if (name == "continue_plane") {
        p.light_transport.continue_plane = value.cast<bool>();
      } else if (name == "indirect_scale") {
        p.light_transport.indirect_scaled = value.cast<bool>();
      } else if (name == "indirect_specular") {
        p.light_transport.indirect_specular =
            reflectance::parse_indirect_specular(value.cast<std::string>());
      } else if (name == "ray_offset") {
        p.light_transport.ray_offset_m = value.cast<float>();
      } else if (name == "seed") {
        p.specular.seed = p.segments.seed = value.cast<std::uint64_t>();
      } else if (name == "render_normal_radius") {
        render_normal_radius = value.cast<float>();
      } else {
        throw Error(name, "", "unknown option of glint.Reconstruction");
      }
    });
  }
  return p;
}

py::dict maps_dict(reflectance::MaterialMaps&& maps) {
  py::dict d;
  d["rgb_refined"] = array_from_image(std::move(maps.rgb_refined));
  d["rgb"] = array_from_image(std::move(maps.rgb));
  d["kd_refined"] = array_from_image(std::move(maps.kd_refined));
  d["kd"] = array_from_image(std::move(maps.kd));
  d["ks"] = array_from_image(std::move(maps.ks));
  d["alpha"] = array_from_image(std::move(maps.alpha));
  d["segment"] = array_from_image(std::move(maps.segment));
  d["covered"] = array_from_image(std::move(maps.covered));
  return d;
}

// The pipeline, its network (which it refers to) and lights; one call at a time.
class Reconstruction {
 public:
  Reconstruction(const py::object& intrinsics, const py::object& lights, const py::kwargs& options)
      : intrinsics_(intrinsics_from(intrinsics)), lights_(lights_from(lights)) {
    std::string model_path;
    params_ = params_from(options, model_path, render_normal_radius_);
    model_path_ = model_path.empty() ? glint::model_path("hemicnn.json").string() : model_path;
    py::gil_scoped_release release;
    network_ = std::make_unique<reflectance::HemiCnn>(reflectance::HemiCnn::load(model_path_));
    pipeline_ = std::make_unique<reflectance::ReflectancePipeline>(intrinsics_, params_, *network_,
                                                                   lights_.lights);
  }

  py::dict add_frame(const py::object& rgb, const py::object& depth, const py::object& pose,
                     const py::object& segments) {
    io::RgbdFrame frame;
    frame.colour = image_from_array(rgb, "rgb");
    frame.depth_m = image_from_array(depth, "depth");
    if (frame.colour.channels() != 3) throw Error("rgb", "", "must have 3 channels (H, W, 3)");
    if (frame.depth_m.channels() != 1) throw Error("depth", "", "must have one channel (H, W)");
    if (!pose.is_none()) frame.ground_truth = pose_from(pose, "pose");
    std::optional<Image<std::int32_t>> labels;
    if (!segments.is_none()) labels = labels_from_array(segments, "segments");
    reflectance::ReflectanceFrame result;
    {
      py::gil_scoped_release release;
      std::lock_guard lock(mutex_);
      frame.index = std::size_t(pipeline_->frames_processed());
      result = pipeline_->process(frame, labels ? &*labels : nullptr);
    }
    py::dict stats;
    stats["frame"] = frame.index;
    stats["integrated"] = result.geometry.integrated;
    stats["pose"] = pose_array(result.geometry.camera_to_world);
    if (result.geometry.tracking) {
      const fusion::TrackingResult& t = *result.geometry.tracking;
      py::dict tracking;
      tracking["tracked"] = t.status == fusion::TrackingStatus::tracked;
      tracking["inliers"] = t.inliers;
      tracking["rmse_m"] = t.rmse_m;
      stats["tracking"] = tracking;
    } else {
      stats["tracking"] = py::none();
    }
    stats["visible_blocks"] = result.geometry.visible_blocks;
    stats["observed_voxels"] = result.observed_voxels;
    stats["segments"] = result.segments;
    return stats;
  }

  py::object materials() {
    nlohmann::json json;
    {
      py::gil_scoped_release release;
      std::lock_guard lock(mutex_);
      json = reflectance::materials_json(*pipeline_);
    }
    return json_to_python(json);
  }

  py::dict mesh() {
    fusion::TriangleMesh mesh;
    {
      py::gil_scoped_release release;
      std::lock_guard lock(mutex_);
      mesh = reflectance::material_mesh(*pipeline_);
    }
    py::dict d;
    const auto n = py::ssize_t(mesh.vertices.size());
    d["vertices"] = array_from_vectors(std::move(mesh.vertices));
    d["faces"] = array_from_vectors(std::move(mesh.triangles));
    d["colours"] = array_from_vectors(std::move(mesh.colours));
    // kd_r/g/b, ks_r/g/b, alpha, scalar_segment, interleaved into (V, 3) / (V,) arrays.
    std::vector<float> kd(3 * n), ks(3 * n);
    for (int c = 0; c < 3; ++c)
      for (py::ssize_t i = 0; i < n; ++i) {
        kd[3 * i + c] = mesh.vertex_properties[c].second[i];
        ks[3 * i + c] = mesh.vertex_properties[3 + c].second[i];
      }
    d["kd"] = array_from_vector(std::move(kd), {n, 3});
    d["ks"] = array_from_vector(std::move(ks), {n, 3});
    d["alpha"] = array_from_vector(std::move(mesh.vertex_properties[6].second));
    std::vector<std::int32_t> segment(mesh.vertex_properties[7].second.begin(),
                                      mesh.vertex_properties[7].second.end());
    d["segment"] = array_from_vector(std::move(segment));
    return d;
  }

  reflectance::MaterialMaps render_maps(const py::object& pose_arg, const py::object& depth_arg) {
    const Pose pose = pose_from(pose_arg, "pose");
    std::optional<ImageF> depth;
    if (!depth_arg.is_none()) depth = image_from_array(depth_arg, "depth");
    reflectance::MaterialMaps maps;
    py::gil_scoped_release release;
    std::lock_guard lock(mutex_);
    StageTimings timings;
    reflectance::render_model(*pipeline_, intrinsics_, pose, render_normal_radius_, timings, maps,
                              depth ? &*depth : nullptr);
    return maps;
  }

  void export_to(const py::object& path_arg) {
    const std::string path = path_from(path_arg);
    py::gil_scoped_release release;
    std::lock_guard lock(mutex_);
    reflectance::ReconstructionFolder folder(path);
    reflectance::write_reconstruction(folder.path(), *pipeline_, lights_);
    folder.commit();
  }

  int frames() const { return pipeline_->frames_processed(); }
  const std::string& model_path() const { return model_path_; }
  py::dict timings() {
    std::lock_guard lock(mutex_);
    py::dict d;
    const nlohmann::json stages = pipeline_->timings().to_json();
    for (const auto& [stage, figures] : stages.items())
      d[py::str(stage)] = figures["median"].get<double>();
    return d;
  }
  float indirect_scale() {
    std::lock_guard lock(mutex_);
    return pipeline_->light_transport().indirect_scale();
  }

 private:
  Intrinsics intrinsics_;
  reflectance::LightEstimate lights_;
  reflectance::ReflectanceParams params_;
  float render_normal_radius_ = reflectance::kRenderNormalRadiusM;
  std::string model_path_;
  std::unique_ptr<reflectance::HemiCnn> network_;
  std::unique_ptr<reflectance::ReflectancePipeline> pipeline_;
  std::mutex mutex_;
};

}  // namespace

void bind_reconstruction(py::module_ m) {
  py::class_<Reconstruction>(m, "Reconstruction", R"(The online reflectance pipeline of
`glint reconstruct` (paper 1), fed one RGB-D frame at a time.

Reconstruction(intrinsics, lights, **options)

Args:
    intrinsics: dict width, height, fx, fy, cx, cy (pixels), e.g. RgbdSequence.intrinsics.
    lights: the scene's point lights: a lights.json or a light-capture sequence folder (as
        --lights), or a list of dicts {'position': [x, y, z] (metres), 'intensity': [r, g, b],
        'radius_m': 0.03 (optional)}.

Keyword options (the CLI's names, '_' for '-', and its defaults):
    model=None (the shipped hemicnn.json), gt_poses=False (True: every frame's pose is used
    instead of tracking), exposure=1 (radiance = pixel / exposure), obs_voxel=0.02,
    obs_voxels, obs_spacing=1, obs_spacing_frames=2, voxel=0.005, trunc=0.02,
    trunc_per_depth=0.005, depth_max=6, blocks=262144, far_every, far_voxel_pixels,
    track_model_halvings, device='auto', segment_noise=0.5, albedo_every=4,
    albedo_average='median', albedo_keep_clipped=False, albedo_min_cosine=0.2,
    albedo_max_ratio=3, albedo_max_indirect=0.5, albedo_shrinkage=True, albedo_normal_error=0.05,
    albedo_smoothing=0.2, shadows=True, shadow_test=True, shadow_test_sigmas=2, indirect=True,
    indirect_scale=True, indirect_specular='mirror', unseen_light=False, indirect_rays=64,
    indirect_rays_per_frame=2, indirect_pooling=True, continue_plane=True, ray_offset=0.01,
    specular='hemicnn+fit' ('hemicnn'), normals='plane' ('gradient'), seed=1,
    render_normal_radius=0.02.

Calls on one object are serialised (a lock); the GIL is released while each runs, so other
Python threads (another Reconstruction, I/O) go on meanwhile.

Raises:
    glint.Error: bad intrinsics, lights or option values, an unreadable model.)")
      .def(py::init<const py::object&, const py::object&, const py::kwargs&>(),
           py::arg("intrinsics"), py::arg("lights"))
      .def("add_frame", &Reconstruction::add_frame, py::arg("rgb"), py::arg("depth"),
           py::arg("pose") = py::none(), py::arg("segments") = py::none(),
           R"(Process one frame: fuse the geometry, collect observations, segment, estimate the
segments' materials and refine the albedo.

Args:
    rgb: (H, W, 3) linear RGB in [0, 1] (float32/float64; uint8/uint16 are divided by
        255 / 65535 and not sRGB-decoded); copied once into planes.
    depth: (H, W) metres, 0 = no measurement; copied once.
    pose: (4, 4) camera-to-world; required with gt_poses=True; without it, the first frame
        is placed at its pose (or the identity) and later ones are tracked.
    segments: (H, W) integer ground-truth segment ids to use instead of the depth
        segmentation (as --gt-segmentation), or None.

Returns:
    dict: frame (index), integrated (False when tracking was lost and the frame skipped),
    pose (4, 4) camera-to-world used, tracking (dict tracked, inliers, rmse_m, or None),
    visible_blocks, observed_voxels, segments (global segments seen).

Raises:
    glint.Error: sizes other than the intrinsics', a missing pose with gt_poses, a full pool.)")
      .def("materials", &Reconstruction::materials,
           R"(The per-segment materials, as materials.json: dict segments (list of id, kd, ks,
alpha, latest, estimates, lobe_fitted, last_frame, voxels, kd_refined_mean) and exposure.)")
      .def("mesh", &Reconstruction::mesh,
           R"(The marching-cubes mesh with per-vertex materials, as mesh.ply.

Returns:
    dict vertices (V, 3) float32 metres, faces (F, 3) int32, colours (V, 3) float32 (refined
    kd, linear), kd (V, 3), ks (V, 3), alpha (V,), segment (V,) int32 (0 = none). vertices,
    faces and colours own the C++ arrays (no copy); kd/ks are interleaved copies.)")
      .def(
          "render",
          [](Reconstruction& self, const py::object& pose, const py::object& depth) {
            return array_from_image(std::move(self.render_maps(pose, depth).rgb_refined));
          },
          py::arg("pose"), py::arg("depth") = py::none(),
          R"(Re-render the model from a (4, 4) camera-to-world pose with the estimated
materials, refined albedo and lights: (H, W, 3) float32 linear RGB (radiance x exposure,
clipped to [0, 1]), what OUT/frames/*-render.png shows. A view of the image; no copy.
depth: optionally the (H, W) depth in metres of a frame fused from that pose, which the ray
cast starts from, as the CLI's per-frame re-renderings do (without it the ray cast starts at
the camera, and the surface found differs slightly).)")
      .def(
          "render_maps",
          [](Reconstruction& self, const py::object& pose, const py::object& depth) {
            return maps_dict(self.render_maps(pose, depth));
          },
          py::arg("pose"), py::arg("depth") = py::none(),
          R"(All maps of a re-rendering (pose and depth as render()): dict rgb_refined, rgb (HemiCNN kd), kd_refined, kd, ks
((H, W, 3)), alpha, covered ((H, W) float32), segment ((H, W) int32).)")
      .def("export", &Reconstruction::export_to, py::arg("path"),
           R"(Write OUT/mesh.ply, OUT/materials.json and OUT/lights.json as `glint reconstruct`
does, whole: into a temporary folder renamed onto OUT. OUT is replaced only when missing,
empty or a previous reconstruction. (The CLI's per-frame pictures and report are its own.))")
      .def_property_readonly("frames", &Reconstruction::frames, "Frames processed so far.")
      .def_property_readonly("model", &Reconstruction::model_path, "The HemiCNN model file used.")
      .def("timings", &Reconstruction::timings,
           "Median milliseconds per frame of each stage run so far (geometry, observations,\n"
           "segmentation, shadows, indirect, specular, mirror, albedo, total), as the CLI's\n"
           "report.")
      .def_property_readonly(
          "indirect_scale", &Reconstruction::indirect_scale,
          "The scale of the gathered indirect light (indirect_scale=True): what the voxels no\n"
          "light reaches directly show, 0 where they are black; 1 when not scaled. At its cap,\n"
          "2, they are at least twice as bright as the gathered light explains: a light may be\n"
          "missing from `lights` (`glint reconstruct` warns of it).");
}

}  // namespace glint::python
