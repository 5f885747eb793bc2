#pragma once
// Image<T>: a multi-channel raster with any number of channels (material maps have more than
// three). Planar storage, channel-major (one contiguous plane per channel, rows top to
// bottom): per-channel filters stream through memory and the layout is libtorch's CHW.
#include <cstddef>
#include <vector>

namespace glint {

template <class T>
class Image {
 public:
  Image() = default;
  Image(int width, int height, int channels, T fill = T{})
      : width_(width),
        height_(height),
        channels_(channels),
        data_(static_cast<std::size_t>(width) * height * channels, fill) {}

  int width() const { return width_; }
  int height() const { return height_; }
  int channels() const { return channels_; }
  std::size_t pixel_count() const { return static_cast<std::size_t>(width_) * height_; }
  bool empty() const { return data_.empty(); }
  bool same_size(const Image& other) const {
    return width_ == other.width_ && height_ == other.height_;
  }
  // Makes this a width x height image of `channels`: zero-filled where its size changes; where it
  // has that size already it keeps its storage and values (per-frame buffers, reused).
  void ensure_size(int width, int height, int channels) {
    if (width != width_ || height != height_ || channels != channels_)
      *this = Image(width, height, channels);
  }

  T& at(int x, int y, int c) { return data_[index(x, y, c)]; }
  const T& at(int x, int y, int c) const { return data_[index(x, y, c)]; }

  // The c-th channel plane: pixel_count() values, row-major.
  T* plane(int c) { return data_.data() + static_cast<std::size_t>(c) * pixel_count(); }
  const T* plane(int c) const { return data_.data() + static_cast<std::size_t>(c) * pixel_count(); }

  std::vector<T>& values() { return data_; }
  const std::vector<T>& values() const { return data_; }

 private:
  std::size_t index(int x, int y, int c) const {
    return (static_cast<std::size_t>(c) * height_ + y) * width_ + x;
  }

  int width_ = 0;
  int height_ = 0;
  int channels_ = 0;
  std::vector<T> data_;
};

using ImageF = Image<float>;

}  // namespace glint
