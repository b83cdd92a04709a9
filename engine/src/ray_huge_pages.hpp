// An allocator for the ray index's large arrays that a ray reads at random places (the wide BVH's nodes, the leaf
// records): backed by 2 MiB-aligned anonymous mappings marked MADV_HUGEPAGE, so that the kernel may map them with
// transparent huge pages when the system allows it (`/sys/kernel/mm/transparent_hugepage/enabled` set to `always` or
// `madvise`). A ray over a 100k-object scene touches ~20 nodes and a few leaf records scattered over ~20 MB: with
// 4 KiB pages that is more pages than the second-level TLB maps, so most of those loads also walk the page table
// (two-dimensional walks under a hypervisor); a few 2 MiB pages cover the whole tree. Only the placement of the memory
// changes, never its contents, so results are bitwise the same whatever the kernel decides (huge pages, small pages,
// or no THP at all: madvise's failure is ignored). Arrays below kHugePageMin use the ordinary allocator: rounding
// them up to 2 MiB would waste more than their TLB misses cost.
#pragma once

#include <cstddef>
#include <cstdint>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace batchcol::detail {

constexpr std::size_t kHugePageBytes = std::size_t(1) << 21;
constexpr std::size_t kHugePageMin = std::size_t(1) << 20;

inline std::size_t huge_page_round_up(std::size_t bytes) {
  return (bytes + kHugePageBytes - 1) & ~(kHugePageBytes - 1);
}

/// `bytes` of memory aligned to `alignment`; from kHugePageMin on (Linux) a mapping of its own, 2 MiB-aligned and
/// advised for huge pages. Throws std::bad_alloc.
inline void* huge_page_allocate(std::size_t bytes, std::size_t alignment) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (bytes >= kHugePageMin) {
    const std::size_t size = huge_page_round_up(bytes);
    if (size < bytes) throw std::bad_alloc();
    // Over-map by one huge page and cut the mapping down to an aligned window: mmap only promises 4 KiB alignment.
    const std::size_t reserve = size + kHugePageBytes;
    void* raw = mmap(nullptr, reserve, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (raw == MAP_FAILED) throw std::bad_alloc();
    const std::uintptr_t base = reinterpret_cast<std::uintptr_t>(raw);
    const std::uintptr_t aligned = (base + kHugePageBytes - 1) & ~std::uintptr_t(kHugePageBytes - 1);
    if (aligned > base) munmap(raw, aligned - base);
    const std::size_t tail = reserve - (aligned - base) - size;
    if (tail > 0) munmap(reinterpret_cast<void*>(aligned + size), tail);
    void* p = reinterpret_cast<void*>(aligned);
    (void)madvise(p, size, MADV_HUGEPAGE);  // advice only: without THP the pages are small, the contents the same
    return p;
  }
#endif
  return ::operator new(bytes, std::align_val_t(alignment));
}

inline void huge_page_free(void* p, std::size_t bytes, std::size_t alignment) noexcept {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (bytes >= kHugePageMin) {
    munmap(p, huge_page_round_up(bytes));
    return;
  }
#endif
  ::operator delete(p, std::align_val_t(alignment));
}

template <class T> struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() = default;
  template <class U> HugePageAllocator(const HugePageAllocator<U>&) noexcept {}

  T* allocate(std::size_t n) {
    if (n > std::size_t(-1) / sizeof(T)) throw std::bad_alloc();
    return static_cast<T*>(huge_page_allocate(n * sizeof(T), alignof(T)));
  }
  void deallocate(T* p, std::size_t n) noexcept { huge_page_free(p, n * sizeof(T), alignof(T)); }

  template <class U> bool operator==(const HugePageAllocator<U>&) const noexcept { return true; }
  template <class U> bool operator!=(const HugePageAllocator<U>&) const noexcept { return false; }
};

}  // namespace batchcol::detail
