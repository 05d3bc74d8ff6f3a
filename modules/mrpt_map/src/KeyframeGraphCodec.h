#pragma once
// The keyframe map's binary codec: the keyframes, edges and refined points of a KeyframeGraph
// through an MRPT archive, CKeyframeGraphMap's serialization. The layout of each version is
// described in KeyframeGraphCodec.cpp. Private to the maps module.

#include <slamdunk/graph/KeyframeGraph.h>

#include <mrpt/serialization/CArchive.h>

#include <cstdint>
#include <memory>

namespace slamdunk {

/// Writes the graph in the newest layout (CKeyframeGraphMap::kSerializationVersion). Only the
/// keyframes that have a pose when it starts, and the edges between them: a consistent snapshot
/// even while the SLAM system adds keyframes.
void writeKeyframeGraph(mrpt::serialization::CArchive& out, const KeyframeGraph& graph);

/// Reads a graph written in the layout of `version` (0 or newer; the caller rejects versions
/// newer than this build's). Every value is checked before it is used: corrupt data throws
/// std::runtime_error ("corrupt keyframe map data: ..."), never allocates without bound.
std::shared_ptr<KeyframeGraph> readKeyframeGraph(mrpt::serialization::CArchive& in,
                                                 uint8_t version);

}  // namespace slamdunk
