#include <slamdunk/synthetic/RoundedLoop.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace slamdunk {

namespace {

/// Yaw convention: heading 0 travels along +z, pi/2 along +x.
double headingOf(const Eigen::Vector2d& d) { return std::atan2(d.x(), d.y()); }
Eigen::Vector2d directionOf(double heading) { return {std::sin(heading), std::cos(heading)}; }

double wrapToPi(double a) { return std::remainder(a, 2 * M_PI); }

}  // namespace

RoundedLoop::RoundedLoop(const std::vector<Eigen::Vector2d>& corners, double radius) {
  const size_t n = corners.size();
  if (n < 3) throw std::invalid_argument("a rounded loop needs at least 3 corners");
  if (!(radius > 0)) throw std::invalid_argument("a rounded loop needs a positive corner radius");
  auto side = [&](size_t i) { return corners[(i + 1) % n] - corners[i]; };  // corner i to i+1
  // Turn at each corner (signed, + = to the right) and how far before and after the corner the
  // arc touches the sides.
  std::vector<double> turn(n), tangent(n);
  for (size_t i = 0; i < n; ++i) {
    turn[i] = wrapToPi(headingOf(side(i)) - headingOf(side((i + n - 1) % n)));
    if (std::abs(turn[i]) > M_PI - 1e-6)
      throw std::invalid_argument("a rounded loop cannot turn back on itself");
    tangent[i] = radius * std::tan(std::abs(turn[i]) / 2);
  }
  // Pieces from the end of corner 0's arc: the side to corner 1, corner 1's arc, ... corner 0's.
  for (size_t i = 0; i < n; ++i) {
    const size_t next = (i + 1) % n;
    const double heading = headingOf(side(i));
    const Eigen::Vector2d dir = directionOf(heading);
    const double straight = side(i).norm() - tangent[i] - tangent[next];
    if (straight < 0)
      throw std::invalid_argument("rounded loop: the corner radius does not fit on a side");
    pieces_.push_back({corners[i] + tangent[i] * dir, heading, 0.0, straight, length_});
    length_ += straight;
    const double arc = radius * std::abs(turn[next]);
    pieces_.push_back({corners[next] - tangent[next] * dir, heading,
                       std::copysign(1.0 / radius, turn[next]), arc, length_});
    length_ += arc;
  }
}

RoundedLoop::Point RoundedLoop::at(double distance) const {
  double d = std::fmod(distance, length_);
  if (d < 0) d += length_;
  // The last piece starting at or before d.
  const auto it = std::upper_bound(pieces_.begin(), pieces_.end(), d,
                                   [](double v, const Piece& p) { return v < p.startDistance; });
  const Piece& p = *std::prev(it);
  const double u = d - p.startDistance, h0 = p.startHeading, k = p.curvature;
  Point out;
  if (k == 0) {
    out.position = p.start + u * directionOf(h0);
    out.headingDeg = h0 * 180 / M_PI;
  } else {
    // Integral of the direction (sin h, cos h) while the heading turns at rate k.
    const double h = h0 + k * u;
    out.position =
        p.start + Eigen::Vector2d(std::cos(h0) - std::cos(h), std::sin(h) - std::sin(h0)) / k;
    out.headingDeg = h * 180 / M_PI;
  }
  return out;
}

}  // namespace slamdunk
