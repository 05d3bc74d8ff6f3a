#include <slamdunk/core/AtomicOutput.h>
#include <slamdunk/core/ErrorText.h>
#include <slamdunk/core/TextParsing.h>
#include <slamdunk/core/TumTrajectory.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace slamdunk {

namespace {
[[noreturn]] void fail(const std::string& path, size_t line, const std::string& why) {
  throw std::runtime_error(path + ":" + std::to_string(line) + ": " + why);
}
}  // namespace

Trajectory readTumTrajectory(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open trajectory file '" + path + "'");
  Trajectory traj;
  forEachDataLine(in, [&](std::string& text, size_t lineNo) {
    // Commas are accepted as separators too (some tools write them).
    for (char& c : text)
      if (c == ',') c = ' ';
    std::istringstream fields(text);
    std::vector<double> v;
    std::string tok;
    while (fields >> tok) {
      const std::optional<double> x = parseNumber(tok);
      // Quoted printable: a NUL or control byte would cut or garble the message.
      if (!x) fail(path, lineNo, "'" + printableText(tok) + "' is not a number");
      if (!std::isfinite(*x)) fail(path, lineNo, "non-finite value '" + printableText(tok) + "'");
      v.push_back(*x);
    }
    if (v.size() != 8)
      fail(path, lineNo,
           "expected 8 fields 'timestamp tx ty tz qx qy qz qw', found " + std::to_string(v.size()));
    // Finite is not enough: squared distances of 1e300 m overflow to inf in ATE/RPE. No
    // camera trajectory (not even one in UTM coordinates) comes near a billion metres.
    for (int k = 1; k <= 3; ++k)
      if (std::abs(v[k]) > 1e9) {
        char value[32];
        std::snprintf(value, sizeof value, "%g", v[k]);
        fail(path, lineNo, std::string("position ") + value + " m is beyond +-1e9 m");
      }
    StampedPose sp;
    sp.timestamp = v[0];
    try {
      sp.pose = poseFromTranslationQuaternion(v[1], v[2], v[3], v[4], v[5], v[6], v[7]);
    } catch (const std::exception& e) {
      fail(path, lineNo, e.what());
    }
    traj.push_back(sp);
  });
  if (in.bad()) throw std::runtime_error("read error on trajectory file '" + path + "'");
  return traj;
}

struct TumTrajectoryWriter::Impl {
  explicit Impl(const std::string& path) : out(path), file(out.tempPath()) {}
  AtomicOutput out;
  std::ofstream file;
};

TumTrajectoryWriter::TumTrajectoryWriter(const std::string& path, const std::string& headerComment)
    : impl_(std::make_unique<Impl>(path)) {
  std::ofstream& f = impl_->file;
  if (!f) throw std::runtime_error("cannot write trajectory file '" + path + "'");
  if (!headerComment.empty()) {
    std::istringstream lines(headerComment);
    std::string l;
    while (std::getline(lines, l)) f << "# " << l << "\n";
  }
  f << "# timestamp tx ty tz qx qy qz qw\n";
}

TumTrajectoryWriter::~TumTrajectoryWriter() = default;

void TumTrajectoryWriter::add(double timestamp, const Pose& pose) {
  if (!isValidPose(pose))
    throw std::runtime_error("refusing to write an invalid (NaN or non-rigid) pose at t=" +
                             std::to_string(timestamp) + " to '" + impl_->out.targetPath() + "'");
  Eigen::Quaterniond q(pose.linear());
  q.normalize();
  if (q.w() < 0) q.coeffs() *= -1;  // one canonical sign: files diff cleanly between runs
  const Eigen::Vector3d t = pose.translation();
  char buf[256];
  std::snprintf(buf, sizeof(buf), "%.6f %.9g %.9g %.9g %.9g %.9g %.9g %.9g\n", timestamp, t.x(),
                t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  impl_->file << buf;
}

void TumTrajectoryWriter::commit() {
  impl_->file.close();  // flushes; a full disk shows here
  if (!impl_->file)
    throw std::runtime_error("write error on trajectory file '" + impl_->out.targetPath() + "'");
  impl_->out.commit();
}

std::string keyframeTrajectoryPathFor(const std::string& trajectoryPath) {
  const std::filesystem::path p(trajectoryPath);
  return (p.parent_path() / (p.stem().string() + "_keyframes" + p.extension().string())).string();
}

void writeTumTrajectory(const std::string& path, const Trajectory& traj,
                        const std::string& headerComment) {
  TumTrajectoryWriter writer(path, headerComment);
  for (const StampedPose& sp : traj) writer.add(sp.timestamp, sp.pose);
  writer.commit();
}

}  // namespace slamdunk
