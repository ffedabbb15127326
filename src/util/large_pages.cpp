// Large allocations on transparent huge pages. On the virtual machines Lacuna is measured on,
// touching a fresh 4 KiB page costs about 25 us (6.5 s per GB, measured with memset of a new
// 1 GB block), while a 2 MiB huge page costs 0.8 s per GB: a 20 M-triangle mesh and its checks
// touch gigabytes. Kernels set to "madvise" (Debian's default) give huge pages only to ranges
// that ask, so every block of at least 4 MiB that operator new takes from malloc is marked with
// madvise(MADV_HUGEPAGE) before it is used. Memory still comes from and returns to malloc, so the
// default operator delete matches. Linked into the programs (not the libraries), since replacing
// operator new is a whole-program choice.
#include <sys/mman.h>

#include <cstdint>
#include <cstdlib>
#include <new>

namespace {

constexpr std::size_t kLargeBytes = std::size_t{4} << 20;
constexpr std::uintptr_t kPageBytes = 4096;

void* allocate(std::size_t bytes) {
  void* p = std::malloc(bytes ? bytes : 1);
  if (!p) throw std::bad_alloc();
  if (bytes >= kLargeBytes) {
    const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t>(p) + kPageBytes - 1) & ~(kPageBytes - 1);
    const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(kPageBytes - 1);
    if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);  // a hint only
  }
  return p;
}

}  // namespace

void* operator new(std::size_t bytes) { return allocate(bytes); }
void* operator new[](std::size_t bytes) { return allocate(bytes); }
