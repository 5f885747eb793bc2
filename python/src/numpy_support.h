#pragma once
// NumPy arrays in and out of glint's C++ types. Where the layouts differ a copy is made, and
// each function says so:
//   in:  (N, 3) positions -> PointCloud: copied (glint keeps x, y, z as separate arrays);
//        H x W (x C) images -> ImageF: copied (glint keeps one plane per channel);
//   out: std::vector, ImageF, Eigen vector arrays -> arrays that own the C++ storage (moved
//        into the array, never copied); an image comes out as an H x W x C view of its planes.
// Conversions run without the GIL (the caller holds the arrays); malformed input throws
// glint::Error(name, "", reason), which the module turns into glint.Error.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/image.h"
#include "core/point_cloud.h"

namespace glint::python {

namespace py = pybind11;

// An (N, 3) float32 or float64 array of any strides -> a cloud (float64 rounded to float, as
// the file readers do). Non-finite coordinates are an error naming the row.
PointCloud cloud_from_array(const py::handle& xyz, const std::string& name);

// A 2-D (H, W) or 3-D (H, W, C) array of float32/float64 (values as they are) or uint8/uint16
// (divided by 255 / 65535, as io::read_image does), any strides -> a planar ImageF.
ImageF image_from_array(const py::handle& image, const std::string& name);

// A 1-D integer array (any integer dtype) of segment ids (H, W) -> Image<int32>.
Image<std::int32_t> labels_from_array(const py::handle& labels, const std::string& name);

// A float64-convertible array of exactly `rows` x `cols` -> its values row-major.
std::vector<double> matrix_from_array(const py::handle& array, int rows, int cols,
                                      const std::string& name);

// The image as an (H, W, C) float32 array ((H, W) for one channel) over its planes: strides
// (W, 1, H*W) elements. The array owns the image.
py::array array_from_image(ImageF&& image);
py::array array_from_image(Image<std::int32_t>&& image);

// `values` moved into an array of `shape` (C order; default 1-D) that owns them.
template <class T>
py::array array_from_vector(std::vector<T>&& values, std::vector<py::ssize_t> shape = {}) {
  if (shape.empty()) shape = {py::ssize_t(values.size())};
  auto* owned = new std::vector<T>(std::move(values));
  py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<T>*>(p); });
  return py::array_t<T>(shape, owned->data(), owner);
}

// A vector of 3-vectors (Eigen::Vector3f / Vector3i: three packed values each) moved into an
// (N, 3) array that owns it.
template <class Vector>
py::array array_from_vectors(std::vector<Vector>&& vectors) {
  using Scalar = typename Vector::Scalar;
  static_assert(sizeof(Vector) == 3 * sizeof(Scalar), "packed 3-vectors expected");
  auto* owned = new std::vector<Vector>(std::move(vectors));
  py::capsule owner(owned, [](void* p) { delete static_cast<std::vector<Vector>*>(p); });
  return py::array_t<Scalar>({py::ssize_t(owned->size()), py::ssize_t(3)},
                             reinterpret_cast<const Scalar*>(owned->data()), owner);
}

// A path argument: str or os.PathLike.
std::string path_from(const py::handle& path);

// Runs set(value) for keyword option `name`; a value of the wrong type (pybind11's cast_error,
// whose message names neither) becomes glint::Error naming the option and the value.
template <class Set>
void set_option(const std::string& name, const py::handle& value, Set&& set) {
  try {
    set(value);
  } catch (const py::cast_error&) {
    throw Error(name, py::str(py::repr(value)),
                "wrong type for this option (the docstring lists each option's default)");
  }
}

}  // namespace glint::python
