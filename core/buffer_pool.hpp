#pragma once
// Recycled large float buffers (image pyramids). A new frame's pyramid is several MB; taking
// fresh memory for each one costs a page fault per 4 KB page, which measured 20-25 ms per
// 640x480 frame on the 2-core VM (more than tracking it). Buffers returned here are reused
// already mapped. Thread-safe; contents of a reused buffer are stale (callers overwrite).

#include <cstddef>
#include <memory>
#include <mutex>
#include <utility>
#include <vector>

namespace parallax {

class FloatBufferPool {
 public:
  /// Returns a buffer to its pool when the owner releases it.
  struct Return {
    FloatBufferPool* pool = nullptr;
    std::size_t size = 0;
    void operator()(float* data) const { pool->Give(data, size); }
  };
  using Buffer = std::unique_ptr<float[], Return>;

  /// At most `max_free` buffers wait for reuse (more are freed).
  explicit FloatBufferPool(std::size_t max_free) : max_free_(max_free) {}
  ~FloatBufferPool();
  FloatBufferPool(const FloatBufferPool&) = delete;
  FloatBufferPool& operator=(const FloatBufferPool&) = delete;

  /// The pool image pyramids share (lives until exit).
  static FloatBufferPool& Shared();

  /// A buffer of `size` floats (uninitialised): a returned one of that size, or a new one.
  Buffer Take(std::size_t size);
  std::size_t NumFree() const;

 private:
  void Give(float* data, std::size_t size);

  std::size_t max_free_;
  mutable std::mutex mutex_;
  std::vector<std::pair<std::size_t, float*>> free_;  ///< owned; newest last
};

}  // namespace parallax
