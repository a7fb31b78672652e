#include "core/buffer_pool.hpp"

#include <algorithm>

namespace parallax {

FloatBufferPool::~FloatBufferPool() {
  for (const auto& [size, data] : free_) std::default_delete<float[]>()(data);
}

FloatBufferPool& FloatBufferPool::Shared() {
  // Enough for a frame in each stage of the real-time mode plus the recent keyframes'.
  static FloatBufferPool pool(16);
  return pool;
}

FloatBufferPool::Buffer FloatBufferPool::Take(std::size_t size) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    // The most recently returned buffer of the size: the likeliest to be in cache.
    const auto found = std::find_if(free_.rbegin(), free_.rend(),
                                    [&](const auto& entry) { return entry.first == size; });
    if (found != free_.rend()) {
      float* data = found->second;
      free_.erase(std::next(found).base());
      return Buffer(data, Return{this, size});
    }
  }
  return Buffer(std::make_unique_for_overwrite<float[]>(size).release(), Return{this, size});
}

void FloatBufferPool::Give(float* data, std::size_t size) {
  if (data == nullptr) return;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (free_.size() < max_free_) {
      free_.emplace_back(size, data);
      return;
    }
  }
  std::default_delete<float[]>()(data);
}

std::size_t FloatBufferPool::NumFree() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return free_.size();
}

}  // namespace parallax
