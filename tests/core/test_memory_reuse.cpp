// keepFreedMemoryForReuse(): glibc takes both settings (a threshold beyond what it allows would
// be refused, and setting the other one alone would end its own adjustment of both); an
// allocator that ignores them (AddressSanitizer's) is reported as such.

#include <slamdunk/core/MemoryReuse.h>

#include <gtest/gtest.h>

TEST(MemoryReuse, TheSettingsAreTakenOrTheRefusalReported) {
#if defined(__SANITIZE_ADDRESS__)
  EXPECT_FALSE(slamdunk::keepFreedMemoryForReuse()) << "AddressSanitizer's mallopt() refuses";
#elif defined(__GLIBC__)
  EXPECT_TRUE(slamdunk::keepFreedMemoryForReuse());
#else
  EXPECT_FALSE(slamdunk::keepFreedMemoryForReuse()) << "not glibc: nothing to set";
#endif
}
