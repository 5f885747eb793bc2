// glint.edges: BoundED per-point labels and its features, from (N, 3) arrays.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "bindings.h"
#include "core/resources.h"
#include "edges/classifier.h"
#include "edges/features.h"
#include "numpy_support.h"

namespace glint::python {
namespace {

std::vector<int> scales_from(const py::object& scales) {
  return scales.is_none() ? std::vector<int>{} : scales.cast<std::vector<int>>();
}

py::tuple classify(const py::object& xyz, const py::object& model, const py::object& scales_arg) {
  const std::vector<int> scales = scales_from(scales_arg);
  const std::string path =
      model.is_none() ? model_path("bounded-3c.json").string() : path_from(model);
  PointCloud cloud = cloud_from_array(xyz, "xyz");
  edges::Classification result;
  {
    py::gil_scoped_release release;
    result = edges::classify(cloud, edges::Model::load(path), scales);
  }
  // probs: (N, 2), columns p_sharp and p_boundary, interleaved here (one pass over 8 N bytes).
  const std::size_t n = result.labels.size();
  std::vector<float> probs(2 * n);
  for (std::size_t i = 0; i < n; ++i) {
    probs[2 * i] = result.p_sharp[i];
    probs[2 * i + 1] = result.p_boundary[i];
  }
  return py::make_tuple(array_from_vector(std::move(result.labels)),
                        array_from_vector(std::move(probs), {py::ssize_t(n), 2}));
}

py::array features(const py::object& xyz, const py::object& scales_arg, bool angular_gap,
                   bool area_weights) {
  edges::FeatureParams params;
  if (!scales_arg.is_none()) params.scales = scales_from(scales_arg);
  params.angular_gap = angular_gap;
  params.area_weights = area_weights;
  const PointCloud cloud = cloud_from_array(xyz, "xyz");
  edges::FeatureMatrix matrix;
  {
    py::gil_scoped_release release;
    matrix = edges::compute_features(cloud, params);
  }
  const auto rows = py::ssize_t(matrix.points), cols = py::ssize_t(matrix.row_size());
  return array_from_vector(std::move(matrix.values), {rows, cols});
}

}  // namespace

void bind_edges(py::module_ m) {
  m.def("classify", &classify, py::arg("xyz"), py::arg("model") = py::none(),
        py::arg("scales") = py::none(),
        R"(Label every point as non-edge (0), sharp edge (1) or boundary (2) (BoundED).

The same computation as `glint edges classify`: the model's multi-scale neighbourhood
features, then its network.

Args:
    xyz: (N, 3) float32 or float64 positions (any strides; copied once into glint's
        per-axis arrays, float64 rounded to float32 as the file readers do).
    model: path of a model JSON (str or os.PathLike); None = the shipped 3-class model
        bounded-3c.json (bounded-2c.json has no boundary class).
    scales: neighbourhood sizes overriding the model's (same count, largest first), e.g.
        [256, 128, 64, 32] for a cloud much denser than the training data; None = the model's.

Returns:
    (labels, probs): labels (N,) uint8; probs (N, 2) float32 with the softmax probabilities
    of the sharp and boundary classes (boundary 0 for a 2-class model).

Raises:
    glint.Error: bad array shape or dtype, non-finite coordinates, fewer points than the
        largest scale, an unreadable model.

The GIL is released while the features and the network run.)");
  m.def("features", &features, py::arg("xyz"), py::arg("scales") = py::none(),
        py::arg("angular_gap") = false, py::arg("area_weights") = false,
        R"(BoundED's multi-scale neighbourhood features (thesis eqs. 5.1-5.21), as
`glint edges features`.

Args:
    xyz: (N, 3) float32 or float64 positions (copied once, as in classify).
    scales: neighbourhood sizes, largest first; None = [128, 64, 32, 16], the CLI's default.
    angular_gap: also angular_gap per scale (the largest empty sector of the neighbours
        around the normal, as a fraction of the turn), as `--angular-gap`.
    area_weights: weigh each neighbour by the surface it stands for (its squared distance
        to its 8th nearest point relative to the query's, clamped to [1/16, 16]), as
        `--area-weights`.

Returns:
    (N, F * len(scales)) float32, scale-major, F = 12 (13 with angular_gap): per scale
    sigma_upper1..3, sigma_lower1..3, d_perp, d_parallel, s_perp, s_parallel, c_perp,
    c_parallel[, angular_gap]. The array owns the C++ result (no copy).

Raises:
    glint.Error: bad array, bad scales (each >= 3, largest first), too few points.)");
}

}  // namespace glint::python
