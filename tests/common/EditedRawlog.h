#pragma once
// Damaged or re-timed copies of a prepared rawlog, for the tests of hostile input: each frame is
// read, loaded (images embedded in the copy), passed through an edit, and written.

#include <slamdunk/core/RawlogReader.h>
#include <slamdunk/core/RgbdFrame.h>

#include <gtest/gtest.h>
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/serialization/CArchive.h>
#include <opencv2/core.hpp>

#include <string>
#include <type_traits>

namespace slamdunk::test {

/// The first `count` frames of `src`, each passed through edit(index, observation), written to
/// `out`. An edit may return false to leave the frame out.
template <class Edit>
void writeEditedRawlog(const std::string& src, const std::string& out, size_t count, Edit edit) {
  RawlogReader reader(src);
  // Stored, not compressed: the copies hold raw images (1.5 MB a frame), which zlib took most
  // of a test's time over (10 s of 16 for 400 frames at its fastest level).
  mrpt::io::CFileGZOutputStream f(out, mrpt::io::OpenMode::TRUNCATE, 0);
  auto a = mrpt::serialization::archiveFrom(f);
  for (size_t i = 0; i < count; ++i) {
    auto next = reader.next();
    ASSERT_TRUE(next) << src << " has fewer than " << count << " frames";
    const auto obs = selfContainedCopy(*next);
    if constexpr (std::is_same_v<decltype(edit(i, *obs)), bool>) {
      if (!edit(i, *obs)) continue;
    } else {
      edit(i, *obs);
    }
    a << *obs;
  }
}

}  // namespace slamdunk::test
