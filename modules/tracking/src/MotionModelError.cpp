#include <slamdunk/tracking/MotionModelError.h>

#include <algorithm>
#include <cmath>

namespace slamdunk {

MotionModelError::MotionModelError(int window, int minSamples)
    : window_(static_cast<size_t>(std::max(1, window))),
      minSamples_(static_cast<size_t>(std::clamp(minSamples, 1, std::max(1, window)))) {}

void MotionModelError::add(const Twist& predicted, const Twist& measured) {
  const Twist error = predicted - measured;
  if (!error.allFinite()) return;
  errors_.push_back(error);
  if (errors_.size() > window_) errors_.pop_front();
}

std::optional<Twist> MotionModelError::sigma() const {
  if (errors_.size() < minSamples_) return std::nullopt;
  double translation = 0, rotation = 0;
  for (const Twist& e : errors_) {
    translation += e.head<3>().squaredNorm();
    rotation += e.tail<3>().squaredNorm();
  }
  const double axes = 3.0 * static_cast<double>(errors_.size());
  Twist s;
  s.head<3>().setConstant(std::sqrt(translation / axes));
  s.tail<3>().setConstant(std::sqrt(rotation / axes));
  return s;
}

}  // namespace slamdunk
