#include "KeyframeGraphCodec.h"

#include <slamdunk/core/PngHeader.h>
#include <slamdunk/features/CompactDescriptors.h>

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

// Layout, version 1 (all numbers through CArchive, i.e. little-endian):
//   u32 keyframeCount, then per keyframe (increasing id):
//     u32 id, f64 timestamp
//     intrinsics: i32 width, i32 height, f64 fx fy cx cy, f64 dist[5]
//     pose T_world_keyframe (optical frame): f64 x 12 (rotation row-major, then translation)
//     u32 n; per keypoint: f32 x y size angle response, i32 octave class_id
//     descriptors: matrix block (raw)
//     points: n x f64[3]
//     colour: u8 present; if present a matrix block (PNG when 8/16-bit with 1, 3 or 4 channels)
//     depth:  u8 present; if present a matrix block: CV_32F metres, bit-exact either as scaled
//             16-bit PNG (when every pixel is float(k) * units, checked at save time) or raw
//     depthSmall: matrix block (raw, may be 0x0), i32 depthSmallStride
//   u32 edgeCount, then per edge (increasing (i, j), i < j):
//     u32 i, u32 j, u32 m; per match: f64 pointI[3] pointJ[3] weight information[9] (row-major)
//     version 1 adds per match: u32 featureI, featureJ (0xFFFFFFFF: not a feature; version 0
//     maps read as such)
// Version 1 then adds the features' positions refined by the bundle adjustment:
//   u32 count, then per keyframe that has them (increasing id): u32 id, u32 n (its feature
//   count), n x f64[3] (in the keyframe's frame)
// Version 2 has version 1's layout; a keyframe's descriptors may be CV_8S rows (8-bit codes of
// float descriptors, kept by keyframes far from the window), which builds that read up to
// version 1 refuse as corrupt: the version tells them the file is newer instead.
// Version 3 has version 2's layout; descriptors may also be CV_16F rows (half floats, kept by
// the other keyframes), which builds that read up to version 2 refuse as corrupt.
// Matrix block: i32 rows, i32 cols, i32 cv type, u8 encoding (0 raw, 1 PNG, 2 scaled 16-bit
// PNG followed by f32 units), u64 byte count, bytes. Raw bytes are the matrix' own (little-endian
// on every platform this builds on).

namespace slamdunk {

namespace {

enum class MatEncoding : uint8_t { Raw = 0, Png = 1, ScaledU16Png = 2 };

// Depth from 16-bit sensors is float(k) * units (RgbdFrame's own arithmetic): such images are
// stored as k in a 16-bit PNG, 3-4x smaller than raw floats, but only after checking that
// decoding gives back every pixel bit for bit; anything else is stored raw.
constexpr float kDepthUnitCandidates[] = {1e-3f, 1.0f / 5000.0f, 1e-4f, 2e-4f, 5e-4f};

// Limits that reject corrupt sizes before allocating: far above any real RGB-D frame.
constexpr int kMaxImageSide = 1 << 15;
constexpr uint64_t kMaxBlobBytes = uint64_t(1) << 31;
constexpr uint32_t kMaxCount = 100'000'000;

[[noreturn]] void corrupt(const std::string& what) {
  throw std::runtime_error("corrupt keyframe map data: " + what);
}

void readExact(mrpt::serialization::CArchive& in, void* data, size_t n) {
  if (n == 0) return;
  if (in.ReadBuffer(data, n) != n) corrupt("unexpected end of data");
}

uint32_t readCount(mrpt::serialization::CArchive& in, const char* what) {
  const auto n = in.ReadAs<uint32_t>();
  if (n > kMaxCount) corrupt(std::string("implausible ") + what + " count " + std::to_string(n));
  return n;
}

template <typename Vec>
void writeVec(mrpt::serialization::CArchive& out, const Vec& v) {
  for (int k = 0; k < v.size(); ++k) out << double(v[k]);
}

Eigen::Vector3d readVec3(mrpt::serialization::CArchive& in) {
  Eigen::Vector3d v;
  for (int k = 0; k < 3; ++k) in >> v[k];
  return v;
}

bool pngEncodable(const cv::Mat& m) {
  const int depth = m.depth(), ch = m.channels();
  return (depth == CV_8U || depth == CV_16U) && (ch == 1 || ch == 3 || ch == 4);
}

/// k per pixel if every pixel of a CV_32F image is exactly float(k) * units, k in [0, 65535].
std::optional<cv::Mat> exactU16(const cv::Mat& depth, float units) {
  cv::Mat k(depth.rows, depth.cols, CV_16U);
  for (int r = 0; r < depth.rows; ++r) {
    const float* d = depth.ptr<float>(r);
    uint16_t* o = k.ptr<uint16_t>(r);
    for (int c = 0; c < depth.cols; ++c) {
      const double q = std::round(double(d[c]) / double(units));
      if (!(q >= 0 && q <= 65535)) return std::nullopt;  // also rejects NaN
      o[c] = uint16_t(q);
      const float back = float(o[c]) * units;
      if (std::memcmp(&back, &d[c], sizeof back) != 0) return std::nullopt;
    }
  }
  return k;
}

void writeMat(mrpt::serialization::CArchive& out, const cv::Mat& m, bool preferPng) {
  const cv::Mat c = m.isContinuous() ? m : m.clone();
  out << int32_t(c.rows) << int32_t(c.cols) << int32_t(c.type());
  if (preferPng && !c.empty() && pngEncodable(c)) {
    std::vector<uchar> png;
    // Lossless whatever the compression level; 1 keeps saving fast.
    if (!cv::imencode(".png", c, png, {cv::IMWRITE_PNG_COMPRESSION, 1}))
      throw std::runtime_error("could not PNG-encode a keyframe image");
    out << uint8_t(MatEncoding::Png) << uint64_t(png.size());
    out.WriteBuffer(png.data(), png.size());
    return;
  }
  const uint64_t bytes = uint64_t(c.total()) * c.elemSize();
  out << uint8_t(MatEncoding::Raw) << bytes;
  if (bytes) out.WriteBuffer(c.data, bytes);
}

/// Depth (CV_32F metres): as scaled 16-bit PNG when provably exact, else raw.
void writeDepth(mrpt::serialization::CArchive& out, const cv::Mat& depth) {
  if (depth.type() == CV_32F && !depth.empty()) {
    for (float units : kDepthUnitCandidates) {
      const std::optional<cv::Mat> k = exactU16(depth, units);
      if (!k) continue;
      std::vector<uchar> png;
      if (!cv::imencode(".png", *k, png, {cv::IMWRITE_PNG_COMPRESSION, 1})) break;
      out << int32_t(depth.rows) << int32_t(depth.cols) << int32_t(CV_32F)
          << uint8_t(MatEncoding::ScaledU16Png) << units << uint64_t(png.size());
      out.WriteBuffer(png.data(), png.size());
      return;
    }
  }
  writeMat(out, depth, false);
}

/// The next n bytes, read in chunks: memory grows with the data actually present, so a corrupt
/// byte count fails at the end of the data instead of allocating gigabytes first.
std::vector<uchar> readBlob(mrpt::serialization::CArchive& in, uint64_t n) {
  constexpr uint64_t kChunk = uint64_t(1) << 20;
  std::vector<uchar> out;
  while (out.size() < n) {
    const size_t at = out.size(), len = size_t(std::min(kChunk, n - at));
    out.resize(at + len);
    readExact(in, out.data() + at, len);
  }
  return out;
}

cv::Mat readMat(mrpt::serialization::CArchive& in, const char* what) {
  const auto rows = in.ReadAs<int32_t>();
  const auto cols = in.ReadAs<int32_t>();
  const auto type = in.ReadAs<int32_t>();
  const auto encoding = in.ReadAs<uint8_t>();
  const float units = encoding == uint8_t(MatEncoding::ScaledU16Png) ? in.ReadAs<float>() : 0.0f;
  const auto bytes = in.ReadAs<uint64_t>();
  const int depth = CV_MAT_DEPTH(type), channels = CV_MAT_CN(type);
  if (rows < 0 || cols < 0 || uint32_t(rows) > kMaxCount || cols > kMaxImageSide || type < 0 ||
      type >= (CV_CN_MAX << CV_CN_SHIFT) || channels < 1 || depth > CV_16F || bytes > kMaxBlobBytes)
    corrupt(std::string("bad ") + what + " header");
  // Every size is checked before anything is allocated.
  const uint64_t rawBytes = uint64_t(rows) * uint64_t(cols) * uint64_t(CV_ELEM_SIZE(type));
  if (rawBytes > kMaxBlobBytes) corrupt(std::string(what) + " is implausibly large");
  if (encoding == uint8_t(MatEncoding::Raw)) {
    if (bytes != rawBytes) corrupt(std::string(what) + " size disagrees with its byte count");
    const std::vector<uchar> data = readBlob(in, bytes);
    cv::Mat m(rows, cols, type);
    if (bytes) std::memcpy(m.data, data.data(), bytes);
    return m;
  }
  if (encoding != uint8_t(MatEncoding::Png) && encoding != uint8_t(MatEncoding::ScaledU16Png))
    corrupt(std::string("unknown ") + what + " encoding");
  const std::vector<uchar> png = readBlob(in, bytes);
  // The decoder allocates what the PNG header declares: check it against the recorded size.
  const auto declared = pngSize(png.data(), png.size());
  if (!declared || declared->width != uint32_t(cols) || declared->height != uint32_t(rows))
    corrupt(std::string(what) + " PNG header does not match the recorded size " +
            std::to_string(cols) + "x" + std::to_string(rows));
  cv::Mat m = cv::imdecode(png, cv::IMREAD_UNCHANGED);
  if (encoding == uint8_t(MatEncoding::ScaledU16Png)) {
    if (type != CV_32F || m.type() != CV_16U || !(units > 0) || !std::isfinite(units * 65535.0f))
      corrupt(std::string(what) + " scaled 16-bit PNG is inconsistent");
    cv::Mat depthOut(m.rows, m.cols, CV_32F);
    for (int r = 0; r < m.rows; ++r) {
      const uint16_t* k = m.ptr<uint16_t>(r);
      float* d = depthOut.ptr<float>(r);
      for (int c = 0; c < m.cols; ++c) d[c] = float(k[c]) * units;  // as checked when saved
    }
    m = depthOut;
  }
  if (m.rows != rows || m.cols != cols || m.type() != type)
    corrupt(std::string(what) + " PNG does not decode to the recorded size and type");
  return m;
}

bool allFinite(const cv::Mat& m) {
  if (m.empty()) return true;
  cv::Mat f;
  m.convertTo(f, CV_32F);
  return cv::checkRange(f, true, nullptr, -FLT_MAX, FLT_MAX);
}

bool nonNegativeFinite(const cv::Mat& m) {
  if (m.empty()) return true;
  cv::Mat f;
  m.convertTo(f, CV_32F);
  return cv::checkRange(f, true, nullptr, 0.0, FLT_MAX);
}

/// What the pipeline relies on in a keyframe it did not build itself (the file may be corrupt in
/// ways the framing does not show): usable intrinsics, a rigid pose, finite features with a
/// descriptor row each, and a subsampled depth that matches the intrinsics.
void validateKeyframe(const Keyframe& kf, const Pose& pose) {
  const std::string k = "keyframe " + std::to_string(kf.id);
  if (!std::isfinite(kf.timestamp)) corrupt(k + ": timestamp is not finite");
  if (const std::string bad = kf.intrinsics.problem(); !bad.empty())
    corrupt(k + ": camera intrinsics: " + bad);
  const Eigen::Matrix3d R = pose.linear();
  if (!pose.matrix().allFinite() ||
      (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-3 ||
      !(R.determinant() > 0))
    corrupt(k + ": pose is not a rigid transform");
  const FeatureSet& f = kf.features;
  for (const cv::KeyPoint& p : f.keypoints)
    if (!std::isfinite(p.pt.x) || !std::isfinite(p.pt.y) || !std::isfinite(p.size) ||
        !std::isfinite(p.angle) || !std::isfinite(p.response))
      corrupt(k + ": a keypoint has a non-finite value");
  for (const Eigen::Vector3d& p : f.points)
    if (!p.allFinite()) corrupt(k + ": a feature point is not finite");
  if (!f.keypoints.empty()) {
    const int t = f.descriptors.type();
    if (f.descriptors.cols < 1 ||
        (t != CV_32FC1 && t != CV_16FC1 && t != CV_8UC1 && !compactDescriptorType(t)))
      corrupt(k +
              ": descriptors must be a CV_32F, CV_16F, CV_8U or CV_8S matrix with one row "
              "per keypoint");
    if ((t == CV_32FC1 || t == CV_16FC1) && !allFinite(f.descriptors))
      corrupt(k + ": a descriptor is not finite");
  }
  // The full images are stored bit-exact whatever they hold (their readers check sizes and
  // skip invalid depth); only their kinds are fixed. The subsampled depth is indexed through
  // the intrinsics by the tracker: its size and values must be right.
  if (!kf.depth.empty() && kf.depth.type() != CV_32FC1)
    corrupt(k + ": depth image must be CV_32F metres");
  const CameraIntrinsics& K = kf.intrinsics;
  if (!kf.depthSmall.empty()) {
    const int s = kf.depthSmallStride;
    if (s < 1 || s > 64) corrupt(k + ": subsampled depth stride " + std::to_string(s));
    if (kf.depthSmall.type() != CV_16FC1 && kf.depthSmall.type() != CV_32FC1)
      corrupt(k + ": subsampled depth must be CV_16F or CV_32F");
    if (kf.depthSmall.rows != (K.height + s - 1) / s || kf.depthSmall.cols != (K.width + s - 1) / s)
      corrupt(k + ": subsampled depth does not match the camera's size and its stride");
    if (!nonNegativeFinite(kf.depthSmall))
      corrupt(k + ": subsampled depth has negative or non-finite values");
  }
}

void writeKeyframe(mrpt::serialization::CArchive& out, const Keyframe& kf, const Pose& pose) {
  out << uint32_t(kf.id) << kf.timestamp;
  const CameraIntrinsics& K = kf.intrinsics;
  out << int32_t(K.width) << int32_t(K.height) << K.fx << K.fy << K.cx << K.cy;
  for (double d : K.dist) out << d;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out << pose.linear()(r, c);
  writeVec(out, pose.translation());

  const FeatureSet& f = kf.features;
  out << uint32_t(f.keypoints.size());
  for (const cv::KeyPoint& k : f.keypoints)
    out << k.pt.x << k.pt.y << k.size << k.angle << k.response << int32_t(k.octave)
        << int32_t(k.class_id);
  writeMat(out, f.descriptors, false);
  out << uint32_t(f.points.size());
  for (const Eigen::Vector3d& p : f.points) writeVec(out, p);

  out << uint8_t(!kf.colour.empty());
  if (!kf.colour.empty()) writeMat(out, kf.colour, true);
  out << uint8_t(!kf.depth.empty());
  if (!kf.depth.empty()) writeDepth(out, kf.depth);
  writeMat(out, kf.depthSmall, false);
  out << int32_t(kf.depthSmallStride);
}

std::pair<std::shared_ptr<Keyframe>, Pose> readKeyframe(mrpt::serialization::CArchive& in) {
  auto kf = std::make_shared<Keyframe>();
  kf->id = in.ReadAs<uint32_t>();
  in >> kf->timestamp;
  CameraIntrinsics& K = kf->intrinsics;
  K.width = in.ReadAs<int32_t>();
  K.height = in.ReadAs<int32_t>();
  in >> K.fx >> K.fy >> K.cx >> K.cy;
  for (double& d : K.dist) in >> d;
  Pose pose = Pose::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) in >> pose.linear()(r, c);
  pose.translation() = readVec3(in);

  FeatureSet& f = kf->features;
  const uint32_t n = readCount(in, "keypoint");
  for (uint32_t k = 0; k < n; ++k) {  // no reserve(n): a corrupt n hits the end of data first
    cv::KeyPoint kp;
    in >> kp.pt.x >> kp.pt.y >> kp.size >> kp.angle >> kp.response;
    kp.octave = in.ReadAs<int32_t>();
    kp.class_id = in.ReadAs<int32_t>();
    f.keypoints.push_back(kp);
  }
  f.descriptors = readMat(in, "descriptor matrix");
  if (!f.descriptors.empty() && uint32_t(f.descriptors.rows) != n)
    corrupt("keyframe " + std::to_string(kf->id) + " has " + std::to_string(n) + " keypoints but " +
            std::to_string(f.descriptors.rows) + " descriptors");
  const uint32_t np = readCount(in, "point");
  if (np != n) corrupt("keyframe " + std::to_string(kf->id) + ": point and keypoint counts differ");
  for (uint32_t k = 0; k < np; ++k) f.points.push_back(readVec3(in));

  if (in.ReadAs<uint8_t>()) kf->colour = readMat(in, "colour image");
  if (in.ReadAs<uint8_t>()) kf->depth = readMat(in, "depth image");
  kf->depthSmall = readMat(in, "subsampled depth image");
  kf->depthSmallStride = in.ReadAs<int32_t>();
  validateKeyframe(*kf, pose);
  return {kf, pose};
}

}  // namespace

void writeKeyframeGraph(mrpt::serialization::CArchive& out, const KeyframeGraph& live) {
  // From a snapshot: consistent even if the SLAM system adds or culls keyframes meanwhile.
  const std::shared_ptr<const KeyframeGraph> snapshot = live.snapshot();
  const KeyframeGraph& graph = *snapshot;
  const auto poses = graph.poses();
  out << uint32_t(poses.size());
  for (const auto& [id, pose] : poses) writeKeyframe(out, *graph.keyframe(id), pose);
  std::vector<KeyframeEdge> edges = graph.allEdges();
  edges.erase(
      std::remove_if(edges.begin(), edges.end(),
                     [&](const KeyframeEdge& e) { return !poses.count(e.i) || !poses.count(e.j); }),
      edges.end());
  out << uint32_t(edges.size());
  for (const KeyframeEdge& e : edges) {
    out << uint32_t(e.i) << uint32_t(e.j) << uint32_t(e.matches.size());
    for (const PointMatch& m : e.matches) {
      writeVec(out, m.pointI);
      writeVec(out, m.pointJ);
      out << m.weight;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) out << m.information(r, c);
      out << m.featureI << m.featureJ;
    }
  }
  std::vector<std::pair<KeyframeId, RefinedPoints>> refined;
  for (const auto& [id, pose] : poses)
    if (RefinedPoints points = graph.refinedPoints(id)) refined.emplace_back(id, std::move(points));
  out << uint32_t(refined.size());
  for (const auto& [id, points] : refined) {
    out << uint32_t(id) << uint32_t(points->size());
    for (const Eigen::Vector3d& p : *points) writeVec(out, p);
  }
}

std::shared_ptr<KeyframeGraph> readKeyframeGraph(mrpt::serialization::CArchive& in,
                                                 uint8_t version) {
  auto graph = std::make_shared<KeyframeGraph>();
  const uint32_t n = readCount(in, "keyframe");
  const Keyframe* withDescriptors = nullptr;  // all keyframes must share one descriptor kind
  for (uint32_t k = 0; k < n; ++k) {
    auto [kf, pose] = readKeyframe(in);
    if (graph->contains(kf->id)) corrupt("keyframe id " + std::to_string(kf->id) + " repeated");
    const cv::Mat& d = kf->features.descriptors;
    if (!d.empty()) {
      if (!withDescriptors) {
        withDescriptors = kf.get();
      } else if (d.cols != withDescriptors->features.descriptors.cols ||
                 kf->features.binary() != withDescriptors->features.binary()) {
        corrupt("keyframes " + std::to_string(withDescriptors->id) + " and " +
                std::to_string(kf->id) + " have descriptors of different kinds");
      }
    }
    graph->addKeyframe(std::move(kf), pose);
  }
  const uint32_t ne = readCount(in, "edge");
  for (uint32_t k = 0; k < ne; ++k) {
    const auto i = in.ReadAs<uint32_t>();
    const auto j = in.ReadAs<uint32_t>();
    const uint32_t m = readCount(in, "match");
    if (i >= j || !graph->contains(i) || !graph->contains(j))
      corrupt("edge " + std::to_string(i) + "-" + std::to_string(j) +
              " does not join two known keyframes in increasing order");
    std::vector<PointMatch> matches;
    for (uint32_t q = 0; q < m; ++q) {
      PointMatch pm;
      pm.pointI = readVec3(in);
      pm.pointJ = readVec3(in);
      in >> pm.weight;
      Eigen::Matrix3d information;  // stored whole; the graph keeps its lower triangle
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) in >> information(r, c);
      pm.information = information;
      if (version >= 1) in >> pm.featureI >> pm.featureJ;
      if (!pm.pointI.allFinite() || !pm.pointJ.allFinite() || !std::isfinite(pm.weight) ||
          pm.weight < 0 || !information.allFinite())
        corrupt("edge " + std::to_string(i) + "-" + std::to_string(j) +
                ": a match has a non-finite or negative value");
      if ((pm.featureI != PointMatch::kNoFeature &&
           pm.featureI >= graph->keyframe(i)->features.size()) ||
          (pm.featureJ != PointMatch::kNoFeature &&
           pm.featureJ >= graph->keyframe(j)->features.size()))
        corrupt("edge " + std::to_string(i) + "-" + std::to_string(j) +
                ": a match names a feature its keyframe does not have");
      matches.push_back(pm);
    }
    graph->addMatches(i, j, matches);  // i < j: stored unchanged
  }
  if (version >= 1) {
    const uint32_t nr = readCount(in, "refined keyframe");
    PointRefinements refined;
    for (uint32_t k = 0; k < nr; ++k) {
      const auto id = in.ReadAs<uint32_t>();
      const uint32_t n = readCount(in, "refined point");
      if (!graph->contains(id) || n != graph->keyframe(id)->features.size() || refined.count(id))
        corrupt("refined points of keyframe " + std::to_string(id) + " do not match its features");
      auto& points = refined[id];
      for (uint32_t q = 0; q < n; ++q) {
        const Eigen::Vector3d p = readVec3(in);
        if (!p.allFinite())
          corrupt("keyframe " + std::to_string(id) + ": a refined point is not finite");
        points.emplace_back(q, p);
      }
    }
    graph->setPoses({}, refined);
  }
  return graph;
}

}  // namespace slamdunk
