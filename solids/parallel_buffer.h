// Buffers (util/buffer.h) made by a parallel pass, so their pages are first touched on every
// thread: one filled with a value, one copied from an array.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>

#include "util/buffer.h"

namespace lacuna {

template <class T>
Buffer<T> filled_buffer(size_t n, T value) {
  Buffer<T> b(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 65536), [&](const tbb::blocked_range<size_t>& range) {
    std::fill(b.data() + range.begin(), b.data() + range.end(), value);
  });
  return b;
}

template <class T>
Buffer<T> copied_buffer(const T* from, size_t n) {
  Buffer<T> b(n);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 65536), [&](const tbb::blocked_range<size_t>& range) {
    std::copy(from + range.begin(), from + range.end(), b.data() + range.begin());
  });
  return b;
}

}  // namespace lacuna
