// glint.io: point clouds, images and RGB-D sequences to and from NumPy arrays, through glint's
// own readers and writers (the ones the CLI uses).
#include <fmt/format.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <variant>

#include "bindings.h"
#include "core/error.h"
#include "edges/classifier.h"
#include "io/image_io.h"
#include "io/point_cloud_io.h"
#include "io/rgbd_sequence.h"
#include "numpy_support.h"
#include "reflectance/light_estimation.h"
#include "reflectance/material_evaluation.h"

namespace glint::python {
namespace {

py::tuple read_point_cloud(const py::object& path_arg) {
  const std::string path = path_from(path_arg);
  PointCloud cloud;
  {
    py::gil_scoped_release release;
    cloud = io::read_point_cloud(path);
  }
  const std::size_t n = cloud.size();
  // A cloud the reader re-centred (far from 0) comes back in float64 with its own coordinates.
  const auto interleave = [&](auto zero) {
    using T = decltype(zero);
    std::vector<T> xyz(3 * n);
    for (std::size_t i = 0; i < n; ++i) {
      xyz[3 * i] = T(cloud.origin.x() + T(cloud.x[i]));
      xyz[3 * i + 1] = T(cloud.origin.y() + T(cloud.y[i]));
      xyz[3 * i + 2] = T(cloud.origin.z() + T(cloud.z[i]));
    }
    return array_from_vector(std::move(xyz), {py::ssize_t(n), 3});
  };
  py::array positions = cloud.origin.isZero() ? interleave(0.0f) : interleave(0.0);
  py::dict fields;
  // Attributes leave the cloud one by one, moved into their arrays.
  std::vector<std::string> names;
  for (const NamedAttribute& attribute : cloud.attributes()) names.push_back(attribute.name);
  for (const std::string& name : names) {
    AttributeColumn column = *cloud.find(name);
    fields[py::str(name)] =
        std::visit([](auto& values) { return array_from_vector(std::move(values)); }, column);
    cloud.remove(name);
  }
  return py::make_tuple(positions, fields);
}

// A 1-D NumPy array of a PLY-representable dtype -> an attribute column (copied).
AttributeColumn column_from(const py::handle& object, const std::string& name, std::size_t n) {
  if (!py::isinstance<py::array>(object)) throw Error(name, "", "must be a 1-D NumPy array");
  const auto array = py::reinterpret_borrow<py::array>(object);
  if (array.ndim() != 1 || std::size_t(array.shape(0)) != n)
    throw Error(name, "", fmt::format("must be a 1-D array of {} values (one per point)", n));
  AttributeColumn column;
  const auto take = [&](auto zero) {
    using T = decltype(zero);
    if (!array.dtype().is(py::dtype::of<T>())) return false;
    const auto contiguous = py::array_t<T, py::array::c_style>::ensure(array);
    column = std::vector<T>(contiguous.data(), contiguous.data() + n);
    return true;
  };
  if (take(std::int8_t{}) || take(std::uint8_t{}) || take(std::int16_t{}) ||
      take(std::uint16_t{}) || take(std::int32_t{}) || take(std::uint32_t{}) || take(float{}) ||
      take(double{}))
    return column;
  throw Error(name, "",
              fmt::format("dtype {} has no PLY type (use int8..uint32, float32 or float64)",
                          std::string(py::str(array.dtype()))));
}

void write_point_cloud(const py::object& path_arg, const py::object& xyz, const py::object& labels,
                       const py::object& probs, const py::object& fields) {
  const std::string path = path_from(path_arg);
  PointCloud cloud = cloud_from_array(xyz, "xyz");
  if (!fields.is_none())
    for (const auto& [key, value] : fields.cast<py::dict>()) {
      const std::string name = py::str(key);
      cloud.set(name, column_from(value, name, cloud.size()));
    }
  if (!labels.is_none()) {
    edges::Classification result;
    const auto label_array = column_from(labels, "labels", cloud.size());
    if (!std::holds_alternative<std::vector<std::uint8_t>>(label_array))
      throw Error("labels", "", "must be uint8 (as classify returns them)");
    result.labels = std::get<std::vector<std::uint8_t>>(label_array);
    result.p_sharp.assign(cloud.size(), 0.0f);
    result.p_boundary.assign(cloud.size(), 0.0f);
    if (!probs.is_none()) {
      const auto p = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(probs);
      if (!p || p.ndim() != 2 || std::size_t(p.shape(0)) != cloud.size() || p.shape(1) != 2)
        throw Error("probs", "", "must be an (N, 2) array (as classify returns it)");
      for (std::size_t i = 0; i < cloud.size(); ++i) {
        result.p_sharp[i] = p.at(i, 0);
        result.p_boundary[i] = p.at(i, 1);
      }
    }
    edges::attach_classification(cloud, result);
  } else if (!probs.is_none()) {
    throw Error("probs", "", "given without labels");
  }
  py::gil_scoped_release release;
  io::write_point_cloud(path, cloud);
}

py::array read_image(const py::object& path_arg) {
  const std::string path = path_from(path_arg);
  ImageF image;
  {
    py::gil_scoped_release release;
    image = io::read_image(path);
  }
  return array_from_image(std::move(image));
}

void write_image(const py::object& path_arg, const py::object& image_arg, int depth) {
  const std::string path = path_from(path_arg);
  if (depth != 8 && depth != 16) throw Error("depth", "", "must be 8 or 16");
  const ImageF image = image_from_array(image_arg, "image");
  py::gil_scoped_release release;
  io::write_image(path, image, depth == 16 ? io::PngDepth::sixteen : io::PngDepth::eight);
}

py::array pose_matrix(const Pose& pose) {
  std::vector<double> values(16);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) values[4 * r + c] = pose.matrix()(r, c);
  return array_from_vector(std::move(values), {4, 4});
}

// An opened sequence, its frames decoded on demand.
struct Sequence {
  io::RgbdSequence sequence;
  bool has_segments = false;
  float exposure = 1;
};

py::dict read_frame(const Sequence& self, py::ssize_t index) {
  const auto count = py::ssize_t(self.sequence.frames.size());
  if (index < 0) index += count;
  if (index < 0 || index >= count) throw py::index_error("frame index out of range");
  io::RgbdFrame frame;
  std::optional<Image<std::int32_t>> segments;
  {
    py::gil_scoped_release release;
    frame = io::read_rgbd_frame(self.sequence, std::size_t(index));
    if (self.has_segments)
      segments = reflectance::read_ground_truth_segments(self.sequence, std::size_t(index));
  }
  py::dict result;
  result["index"] = index;
  result["timestamp"] = frame.timestamp_s;
  result["rgb"] = array_from_image(std::move(frame.colour));
  result["depth"] = array_from_image(std::move(frame.depth_m));
  result["pose"] = frame.ground_truth ? py::object(pose_matrix(*frame.ground_truth)) : py::none();
  result["segments"] =
      segments ? py::object(array_from_image(std::move(*segments))) : py::object(py::none());
  return result;
}

py::dict intrinsics_dict(const Intrinsics& k) {
  py::dict d;
  d["width"] = k.width;
  d["height"] = k.height;
  d["fx"] = k.fx;
  d["fy"] = k.fy;
  d["cx"] = k.cx;
  d["cy"] = k.cy;
  return d;
}

}  // namespace

void bind_io(py::module_ m) {
  m.def("read_point_cloud", &read_point_cloud, py::arg("path"),
        R"(Read a point cloud (.ply, .xyz/.pts/.txt/.csv, .pcd) with glint's readers.

Returns:
    (xyz, fields): xyz (N, 3) float32 positions (interleaved from glint's per-axis arrays;
    float64 for a cloud whose centre lies beyond 1e4 from 0, which glint re-centres on read);
    fields: dict of the per-point properties by name (e.g. 'scalar_label', 'red'), each a
    1-D array of the stored type (copied).

Raises:
    glint.Error: unknown extension, missing or malformed file, non-finite coordinates.)");
  m.def("write_point_cloud", &write_point_cloud, py::arg("path"), py::arg("xyz"),
        py::arg("labels") = py::none(), py::arg("probs") = py::none(),
        py::arg("fields") = py::none(),
        R"(Write a point cloud: binary PLY (.ply) or text (.xyz/.pts/.txt), atomically.

Args:
    path: output file.
    xyz: (N, 3) float32/float64 positions.
    labels, probs: classify()'s output; when given, written as `glint edges classify`
        writes them: uchar scalar_label, float scalar_p_sharp, float scalar_p_boundary and
        red/green/blue (red = sharp, green = boundary).
    fields: dict name -> 1-D array (int8..uint32, float32, float64) of extra properties.

Raises:
    glint.Error: bad arrays, an unsupported extension, an unwritable path.)");
  m.def("read_image", &read_image, py::arg("path"),
        R"(Read an image (PNG 8/16-bit, EXR, .npy, ...) as io::read_image does: integer
samples divided by 255 / 65535, floats as stored, no sRGB decoding.

Returns:
    (H, W, C) float32, or (H, W) for one channel: a view of glint's planar image
    (strides (W, 1, H*W) elements; no copy). np.ascontiguousarray() makes it C-ordered.)");
  m.def("write_image", &write_image, py::arg("path"), py::arg("image"), py::arg("depth") = 8,
        R"(Write an image by extension: .png (values clamped to [0, 1], 8 or 16 bits per
`depth`), .exr (float32) or .npy; atomically. image: (H, W) or (H, W, C) float32/float64
(values as they are) or uint8/uint16 (divided by 255 / 65535); copied once.)");

  py::class_<Sequence>(m, "RgbdSequence", R"(An RGB-D sequence folder (glint synthetic, TUM,
7-Scenes or Redwood layout), as `glint reconstruct` reads it; frames are decoded on demand.

Attributes:
    folder, format: the folder and its detected layout.
    intrinsics: dict width, height, fx, fy, cx, cy (pixels), Reconstruction's argument.
    exposure: the scene.json's camera exposure, else 1 (the CLI's --exposure default).

seq[i] (also negative i; iterating works) returns a dict: rgb (H, W, 3) float32 linear RGB,
depth (H, W) float32 metres (0 = none), pose (4, 4) camera-to-world float64 or None,
segments (H, W) int32 ground-truth segment ids or None, timestamp (s), index.)")
      .def_property_readonly("folder", [](const Sequence& s) { return s.sequence.folder; })
      .def_property_readonly("format", [](const Sequence& s) { return s.sequence.format; })
      .def_property_readonly(
          "intrinsics", [](const Sequence& s) { return intrinsics_dict(s.sequence.intrinsics); })
      .def_property_readonly("exposure", [](const Sequence& s) { return s.exposure; })
      .def("__len__", [](const Sequence& s) { return s.sequence.frames.size(); })
      .def("__getitem__", &read_frame, py::arg("index"));
  m.def(
      "open_rgbd_sequence",
      [](const py::object& folder_arg) {
        const std::string folder = path_from(folder_arg);
        py::gil_scoped_release release;
        Sequence s{io::open_rgbd_sequence(folder)};
        s.has_segments = reflectance::has_ground_truth_maps(s.sequence);
        s.exposure = reflectance::capture_exposure(folder);
        return s;
      },
      py::arg("folder"),
      R"(Open an RGB-D sequence folder; returns a glint.io.RgbdSequence.

Raises:
    glint.Error: no known layout, a missing or malformed index file.)");
}

}  // namespace glint::python
