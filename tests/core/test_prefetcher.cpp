// Prefetcher: items come out in the order they were made, whatever the timing; an error ends
// the sequence at its place; the end and the error stay; destruction stops a producer that is
// ahead.

#include <slamdunk/core/Prefetcher.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

using namespace slamdunk;

TEST(Prefetcher, ItemsComeOutInProductionOrderThenTheEndStays) {
  int made = 0;
  Prefetcher<int> p(
      [&]() -> std::optional<int> {
        if (made == 50) return std::nullopt;
        // Uneven production times: the consumer sometimes waits, sometimes finds items ready.
        if (made % 7 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(2));
        return made++;
      },
      3);
  for (int i = 0; i < 50; ++i) {
    const std::optional<int> item = p.next();
    ASSERT_TRUE(item.has_value()) << "item " << i;
    EXPECT_EQ(*item, i);
    if (i % 11 == 0) std::this_thread::sleep_for(std::chrono::milliseconds(3));
  }
  EXPECT_FALSE(p.next().has_value());
  EXPECT_FALSE(p.next().has_value());  // asking again: still the end
}

TEST(Prefetcher, AnErrorComesAfterTheItemsBeforeItAndStays) {
  int made = 0;
  Prefetcher<int> p(
      [&]() -> std::optional<int> {
        if (made == 3) throw std::runtime_error("entry 3 is damaged");
        return made++;
      },
      8);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(p.next().value(), i);
  for (int attempt = 0; attempt < 2; ++attempt) {
    try {
      p.next();
      FAIL() << "no error after the third item";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "entry 3 is damaged");
    }
  }
  EXPECT_EQ(made, 3);  // nothing produced after the error
}

TEST(Prefetcher, StaysAtMostDepthAheadAndStopsWhenDestroyed) {
  std::atomic<int> made{0};
  {
    Prefetcher<int> p([&]() -> std::optional<int> { return made++; }, 2);
    EXPECT_EQ(p.next().value(), 0);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    // One handed out, two waiting, and the producer asleep until one is taken.
    EXPECT_EQ(made.load(), 3);
  }  // never at the end: destroyed while ahead, without waiting for the sequence
  EXPECT_EQ(made.load(), 3);
}
