// Allocator for the broad phase's large per-frame buffers (cell records, pair words).
//
// Two things the default std::allocator costs on these buffers, measured on the 1M-object stress scene:
//  - resize() value-initialises (zeroes) every new element, a full extra write of the buffer; the broad phase
//    overwrites every element it uses, so construct() here default-initialises (leaves trivial types as they are);
//  - the cell records are written in a scattered order (one stream per grid cell) over tens of MB, and with 4 KiB pages
//    nearly every such write also misses the TLB. Blocks of at least kHugePageBytes are aligned to 2 MiB and their
//    whole 2 MiB pages marked MADV_HUGEPAGE (a hint: the kernel's transparent huge pages in "madvise" mode, the Debian
//    default, honour it; in "never" mode nothing changes but speed). The size is not rounded up: the tail past the
//    last whole 2 MiB page keeps 4 KiB pages, so the bytes held are the bytes asked for.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#include <sys/mman.h>

namespace batchcol::broadphase {

constexpr std::size_t kHugePageBytes = std::size_t{2} << 20;

template <class T>
struct BigBufferAllocator {
  using value_type = T;
  BigBufferAllocator() = default;
  template <class U>
  BigBufferAllocator(const BigBufferAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    const std::size_t bytes = n * sizeof(T);
    if (bytes < kHugePageBytes) {
      void* p = std::malloc(bytes == 0 ? 1 : bytes);
      if (!p) throw std::bad_alloc();
      return static_cast<T*>(p);
    }
    void* p = nullptr;
    if (posix_memalign(&p, kHugePageBytes, bytes) != 0) throw std::bad_alloc();
    madvise(p, bytes / kHugePageBytes * kHugePageBytes, MADV_HUGEPAGE);  // a hint: failure only costs speed
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t) noexcept { std::free(p); }

  // Default-initialisation instead of value-initialisation: no zeroing of trivial element types on resize().
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }

  friend bool operator==(const BigBufferAllocator&, const BigBufferAllocator&) { return true; }
  friend bool operator!=(const BigBufferAllocator&, const BigBufferAllocator&) { return false; }
};

template <class T>
using BigVector = std::vector<T, BigBufferAllocator<T>>;

/// Bytes a BigVector holds.
template <class T>
std::size_t held_bytes(const BigVector<T>& v) {
  return v.capacity() * sizeof(T);
}

/// resize() that allocates exactly n the first time and grows by 1/16 (not x2) later: these buffers hold up to
/// 40 bytes per object, and a doubling would be kept for good.
template <class T>
void resize_tight(BigVector<T>& v, std::size_t n) {
  if (v.capacity() < n) v.reserve(v.capacity() == 0 ? n : n + n / 16);
  v.resize(n);
}

}  // namespace batchcol::broadphase
