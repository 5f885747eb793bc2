#include "numpy_support.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>

#include "core/error.h"

namespace glint::python {
namespace {

std::string shape_text(const py::array& array) {
  std::string text = "(";
  for (py::ssize_t d = 0; d < array.ndim(); ++d)
    text += (d ? ", " : "") + std::to_string(array.shape(d));
  return text + (array.ndim() == 1 ? ",)" : ")");
}

py::array as_array(const py::handle& object, const std::string& name) {
  if (!py::isinstance<py::array>(object))
    throw Error(name, "",
                fmt::format("expected a NumPy array, got {}",
                            std::string(py::str(py::type::of(object).attr("__name__")))));
  return py::reinterpret_borrow<py::array>(object);
}

template <class T>
bool holds(const py::array& array) {
  return array.dtype().is(py::dtype::of<T>());
}

// Element (i, j[, k]) of an array of any strides.
template <class T>
const T& element(const char* base, const py::ssize_t* strides, py::ssize_t i, py::ssize_t j,
                 py::ssize_t k = 0) {
  return *reinterpret_cast<const T*>(base + i * strides[0] + j * strides[1] + k * strides[2]);
}

template <class T>
void fill_cloud(const py::array& array, PointCloud& cloud, const std::string& name) {
  const auto* base = static_cast<const char*>(array.data());
  const py::ssize_t strides[3] = {array.strides(0), array.strides(1), 0};
  const std::size_t n = cloud.size();
  std::size_t bad = n;
  {
    py::gil_scoped_release release;
    for (std::size_t i = 0; i < n; ++i) {
      const T x = element<T>(base, strides, i, 0), y = element<T>(base, strides, i, 1),
              z = element<T>(base, strides, i, 2);
      if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z)) {
        bad = i;
        break;
      }
      cloud.x[i] = float(x);
      cloud.y[i] = float(y);
      cloud.z[i] = float(z);
    }
  }
  if (bad < n) throw Error(name, fmt::format("row {}", bad), "non-finite coordinate");
}

// Samples times `scale` in float arithmetic, as io::read_image's OpenCV conversion does, so an
// integer array gives the values its PNG would.
template <class T>
void fill_image(const py::array& array, ImageF& image, float scale) {
  const auto* base = static_cast<const char*>(array.data());
  const py::ssize_t strides[3] = {array.strides(0), array.strides(1),
                                  array.ndim() == 3 ? array.strides(2) : 0};
  py::gil_scoped_release release;
  for (int c = 0; c < image.channels(); ++c) {
    float* plane = image.plane(c);
    for (int y = 0; y < image.height(); ++y)
      for (int x = 0; x < image.width(); ++x)
        plane[std::size_t(y) * image.width() + x] =
            static_cast<float>(element<T>(base, strides, y, x, c)) * scale;
  }
}

}  // namespace

PointCloud cloud_from_array(const py::handle& object, const std::string& name) {
  const py::array array = as_array(object, name);
  if (array.ndim() != 2 || array.shape(1) != 3)
    throw Error(
        name, "",
        fmt::format("must be an (N, 3) array of positions, got shape {}", shape_text(array)));
  PointCloud cloud;
  cloud.resize(std::size_t(array.shape(0)));
  if (holds<float>(array))
    fill_cloud<float>(array, cloud, name);
  else if (holds<double>(array))
    fill_cloud<double>(array, cloud, name);
  else
    throw Error(
        name, "",
        fmt::format("must be float32 or float64, got {}", std::string(py::str(array.dtype()))));
  return cloud;
}

ImageF image_from_array(const py::handle& object, const std::string& name) {
  const py::array array = as_array(object, name);
  if (array.ndim() != 2 && array.ndim() != 3)
    throw Error(
        name, "",
        fmt::format("must be an (H, W) or (H, W, C) image, got shape {}", shape_text(array)));
  const py::ssize_t height = array.shape(0), width = array.shape(1),
                    channels = array.ndim() == 3 ? array.shape(2) : 1;
  if (height == 0 || width == 0 || channels == 0)
    throw Error(name, "", fmt::format("has no pixels (shape {})", shape_text(array)));
  ImageF image(static_cast<int>(width), static_cast<int>(height), static_cast<int>(channels));
  if (holds<float>(array))
    fill_image<float>(array, image, 1.0f);
  else if (holds<double>(array))
    fill_image<double>(array, image, 1.0f);
  else if (holds<std::uint8_t>(array))
    fill_image<std::uint8_t>(array, image, static_cast<float>(1.0 / 255.0));
  else if (holds<std::uint16_t>(array))
    fill_image<std::uint16_t>(array, image, static_cast<float>(1.0 / 65535.0));
  else
    throw Error(name, "",
                fmt::format("must be float32, float64, uint8 or uint16, got {}",
                            std::string(py::str(array.dtype()))));
  return image;
}

Image<std::int32_t> labels_from_array(const py::handle& object, const std::string& name) {
  const py::array array = as_array(object, name);
  if (array.ndim() != 2 || (array.dtype().kind() != 'i' && array.dtype().kind() != 'u'))
    throw Error(name, "",
                fmt::format("must be an (H, W) integer array, got shape {} of {}",
                            shape_text(array), std::string(py::str(array.dtype()))));
  const auto converted =
      py::array_t<std::int32_t, py::array::c_style | py::array::forcecast>(array);
  Image<std::int32_t> labels(int(array.shape(1)), int(array.shape(0)), 1);
  std::copy_n(converted.data(), labels.values().size(), labels.values().data());
  return labels;
}

std::vector<double> matrix_from_array(const py::handle& object, int rows, int cols,
                                      const std::string& name) {
  const auto array = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(object);
  const bool vector = rows == 1 && array && array.ndim() == 1 && array.shape(0) == cols;
  if (!array ||
      (!vector && (array.ndim() != 2 || array.shape(0) != rows || array.shape(1) != cols)))
    throw Error(name, "", fmt::format("must be a {}x{} array of numbers", rows, cols));
  std::vector<double> values(array.data(), array.data() + std::size_t(rows) * cols);
  for (double v : values)
    if (!std::isfinite(v)) throw Error(name, "", "has a non-finite value");
  return values;
}

py::array array_from_image(ImageF&& image) {
  const py::ssize_t height = image.height(), width = image.width(), channels = image.channels();
  auto* owned = new ImageF(std::move(image));
  py::capsule owner(owned, [](void* p) { delete static_cast<ImageF*>(p); });
  const py::ssize_t item = sizeof(float);
  if (channels == 1)
    return py::array_t<float>({height, width}, {width * item, item}, owned->plane(0), owner);
  return py::array_t<float>({height, width, channels}, {width * item, item, height * width * item},
                            owned->plane(0), owner);
}

py::array array_from_image(Image<std::int32_t>&& image) {
  const py::ssize_t height = image.height(), width = image.width();
  return array_from_vector(std::move(image.values()), {height, width});
}

std::string path_from(const py::handle& path) {
  if (py::isinstance<py::str>(path)) return path.cast<std::string>();
  const py::module_ os = py::module_::import("os");
  return py::str(os.attr("fspath")(path));
}

}  // namespace glint::python
