#pragma once
// Error messages built from outside data: bytes quoted so that a message always prints whole
// (a NUL or control character would cut or garble it), and MRPT's exception text (banner,
// nested "Exception while parsing typed object ..." layers, stack traces) reduced to one line.

#include <string>

namespace slamdunk {

/// s with control and non-ASCII bytes written as \xHH, cut to maxLength characters ("...").
std::string printableText(const std::string& s, size_t maxLength = 60);

/// One line from an MRPT exception's what(): the classes being parsed, outermost first, and the
/// innermost message, e.g. "in mrpt::obs::CObservation3DRangeScan > mrpt::img::TCamera: (EOF?)
/// Cannot read requested number of bytes from stream". Other texts: their first line. Always
/// printable, at most 2000 characters.
std::string summarizeError(const std::string& what);

}  // namespace slamdunk
