// The ordered cast's scratch memory (ray_scene_cast.cpp: ray records, sort words, results, ~130 bytes a ray), kept by
// the RaySceneIndex from one cast to the next. Fresh buffers for every cast made the kernel fault in and clear ~130 MB
// for 1M rays each time (perf: 3.9% of a 10k-hull cast's samples in page clearing, plus the faults); an index is
// usually cast against again and again (a frame after another), so the memory is mapped once, at the size of the
// largest ordered batch so far, and only rewritten after that. Every byte a cast reads it has written first in that
// cast, so results do not depend on what an earlier cast left there.
#pragma once

#include <cstddef>
#include <mutex>

#include "ray_huge_pages.hpp"

namespace batchcol::detail {

class RayCastArena {
 public:
  RayCastArena() = default;
  RayCastArena(const RayCastArena&) = delete;
  RayCastArena& operator=(const RayCastArena&) = delete;
  ~RayCastArena() { release(); }

  /// At least `bytes` bytes aligned to 64 (on huge pages when large); the contents are unspecified. Valid until the
  /// next call or the arena's end. Throws std::bad_alloc.
  void* get(std::size_t bytes) {
    if (bytes > size_) {
      release();
      data_ = huge_page_allocate(bytes, kAlign);
      size_ = bytes;
    }
    return data_;
  }

  /// One cast at a time uses an index's arena (RaySceneIndex::cast is const, and may run concurrently): the others take
  /// an arena of their own (try_lock).
  std::mutex mutex;

 private:
  static constexpr std::size_t kAlign = 64;

  void release() {
    if (data_ != nullptr) huge_page_free(data_, size_, kAlign);
    data_ = nullptr, size_ = 0;
  }

  void* data_ = nullptr;
  std::size_t size_ = 0;
};

}  // namespace batchcol::detail
