#include <slamdunk/core/MemoryReuse.h>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace slamdunk {

bool keepFreedMemoryForReuse() {
#if defined(__GLIBC__)
  // Setting either threshold ends glibc's own adjustment of both, so both are set: blocks up to
  // 32 MiB (the most it allows) come from its heaps, and a heap's free top is never trimmed.
  const bool mmap = mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024) == 1;
  const bool trim = mallopt(M_TRIM_THRESHOLD, 1024 * 1024 * 1024) == 1;
  return mmap && trim;
#else
  return false;
#endif
}

}  // namespace slamdunk
