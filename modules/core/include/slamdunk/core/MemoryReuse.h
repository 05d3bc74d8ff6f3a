#pragma once
// Each frame allocates and frees a few megabytes of images and buffers. By default glibc hands
// freed memory at the top of a heap back to the system, and the next frame's buffers fault the
// same pages in again: on 7-Scenes, three page faults in four and 3 % of the CPU. An application
// that processes frames one after the other (slamdunk-rawlog; a robot application may call it
// too) keeps that memory for the next frame instead: its peak resident memory grows by a few
// megabytes, what it computes does not change.

namespace slamdunk {

/// Process-wide: asks the C library to keep freed memory for reuse instead of returning it to
/// the system, for allocations up to the largest size it allows. Call once, early in main().
/// Returns false where the C library has no such settings (then nothing changes).
bool keepFreedMemoryForReuse();

}  // namespace slamdunk
