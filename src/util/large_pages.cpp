// Large allocations on transparent huge pages, when LACUNA_HUGE_PAGES=1 asks for them. Kernels set to
// "madvise" (Debian's default) give huge pages only to ranges that ask, so then every block of at
// least 4 MiB that operator new takes from malloc is marked with madvise(MADV_HUGEPAGE) before it is
// used. Memory still comes from and returns to malloc, so the default operator delete matches.
// Linked into the programs (not the libraries), since replacing operator new is a whole-program
// choice.
//
// Off by default: what a fresh page costs depends on the machine, and on the virtual machines
// Lacuna is measured on it has gone both ways. On one host a fresh 4 KiB page cost about 25 us (6.5 s
// per GB) against 0.8 s per GB on huge pages; on another (Linux 6.18 guest) 4 KiB pages cost 0.31-0.45
// s per GB while huge pages cost 0.12 s per GB when the guest reused them and 2.5-8 s per GB when it
// took fresh ones, and the walk of 50 000 capsules spent 6.3-8.9 s in the kernel with them against
// 1.7-2.6 s without (41.3-43.9 s against 39.1-39.5 s in all; README, "Memory pages").
#include <sys/mman.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>

namespace {

constexpr std::size_t kLargeBytes = std::size_t{4} << 20;
constexpr std::uintptr_t kPageBytes = 4096;

bool huge_pages_asked() {
  const char* value = std::getenv("LACUNA_HUGE_PAGES");
  return value && std::strcmp(value, "1") == 0;
}

void* allocate(std::size_t bytes) {
  static const bool huge = huge_pages_asked();
  void* p = std::malloc(bytes ? bytes : 1);
  if (!p) throw std::bad_alloc();
  if (huge && bytes >= kLargeBytes) {
    const std::uintptr_t begin = (reinterpret_cast<std::uintptr_t>(p) + kPageBytes - 1) & ~(kPageBytes - 1);
    const std::uintptr_t end = (reinterpret_cast<std::uintptr_t>(p) + bytes) & ~(kPageBytes - 1);
    if (end > begin) madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);  // a hint only
  }
  return p;
}

}  // namespace

void* operator new(std::size_t bytes) { return allocate(bytes); }
void* operator new[](std::size_t bytes) { return allocate(bytes); }
