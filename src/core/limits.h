#pragma once
// The ranges glint accepts for numbers read from files and flags (docs/limits.md). Each is
// checked where the number enters, before it sizes an allocation, a loop or a ray, and a value
// outside fails with one glint::Error naming the file, the field and the allowed range.
#include <Eigen/Core>
#include <cstdint>
#include <string>

#include "core/camera.h"

namespace glint::limits {

// Largest |coordinate| in metres of a scene point, camera, light or pose translation: 100 km.
// Rays and TSDF blocks are float / int32 based; far beyond this Embree's ray validity checks
// fail and voxel-block coordinates overflow.
inline constexpr double kWorldExtentM = 1e5;
// Largest image: pixels in total (16384 x 8192), and per side. Checked from the file's header
// before any pixel is decoded.
inline constexpr std::uint64_t kMaxImagePixels = std::uint64_t(1) << 27;
inline constexpr int kMaxImageSide = 65535;
// Largest focal length, in multiples of the image's larger side (a 0.06 degree field of view).
inline constexpr double kMaxFocalPerSide = 1000;
// Largest per-pixel sample count (environment samples, indirect paths) and bounce count.
inline constexpr int kMaxSamplesPerPixel = 65536;
inline constexpr int kMaxBounces = 64;

// Throws glint::Error(file, element, ...) unless every component is finite and within
// ±kWorldExtentM.
void check_position(const Eigen::Vector3d& position, const std::string& file,
                    const std::string& element);
// Throws unless width x height is within kMaxImageSide and kMaxImagePixels.
void check_image_size(std::int64_t width, std::int64_t height, const std::string& file,
                      const std::string& element);
// Throws unless the image size is allowed, 0 < fx, fy <= kMaxFocalPerSide * the larger side and
// the principal point lies on the image (0 <= cx <= width, 0 <= cy <= height). `element` names
// the intrinsics in the file ("camera.intrinsics"; may be empty).
void check_intrinsics(const Intrinsics& intrinsics, const std::string& file,
                      const std::string& element);
// Throws glint::Error saying that `what` (e.g. "a cloud of 10^12 points") could not be
// allocated and how many bytes it needed: the message a bare std::bad_alloc lacks. (bytes is a
// double: the sizes that fail may not fit size_t.)
[[noreturn]] void throw_out_of_memory(const std::string& what, double bytes);

// Throws unless `value` is an integer in [lowest, highest].
void check_integer(double value, double lowest, double highest, const std::string& file,
                   const std::string& element);

}  // namespace glint::limits
