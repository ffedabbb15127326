// Arrays of plain values for large parallel passes that write every element before reading it.
// A std::vector zeroes its elements in its constructor, on one thread, and the kernel clears each
// new page as it is first touched there too; a Buffer leaves its elements uninitialized, so the
// pages are touched (and cleared) by the parallel pass that fills them.
#pragma once

#include <cstddef>
#include <memory>
#include <type_traits>

namespace lacuna {

template <class T>
class Buffer {
  static_assert(std::is_trivially_default_constructible_v<T> && std::is_trivially_destructible_v<T>,
                "a Buffer holds plain values");

 public:
  Buffer() = default;
  explicit Buffer(size_t n) : data_(n ? new T[n] : nullptr), size_(n) {}  // default-initialized: not zeroed

  T& operator[](size_t i) { return data_[i]; }
  const T& operator[](size_t i) const { return data_[i]; }
  T* data() { return data_.get(); }
  const T* data() const { return data_.get(); }
  size_t size() const { return size_; }
  T* begin() { return data_.get(); }
  T* end() { return data_.get() + size_; }

 private:
  std::unique_ptr<T[]> data_;
  size_t size_ = 0;
};

}  // namespace lacuna
