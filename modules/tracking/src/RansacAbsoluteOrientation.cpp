#include <slamdunk/tracking/RansacAbsoluteOrientation.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <random>

namespace slamdunk {

Pose fitRigidTransform(const std::vector<Eigen::Vector3d>& src,
                       const std::vector<Eigen::Vector3d>& dst,
                       const std::vector<double>* weights) {
  const size_t n = src.size();
  double wsum = 0;
  Eigen::Vector3d ms = Eigen::Vector3d::Zero(), md = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    const double w = weights ? (*weights)[i] : 1.0;
    ms += w * src[i];
    md += w * dst[i];
    wsum += w;
  }
  Pose T = Pose::Identity();
  if (n < 3 || wsum <= 0) return T;
  ms /= wsum;
  md /= wsum;
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    const double w = weights ? (*weights)[i] : 1.0;
    H += w * (src[i] - ms) * (dst[i] - md).transpose();
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  // A reflection is never a camera motion: flip the weakest axis instead.
  if ((svd.matrixV() * svd.matrixU().transpose()).determinant() < 0) D(2, 2) = -1;
  const Eigen::Matrix3d R = svd.matrixV() * D * svd.matrixU().transpose();
  T.linear() = R;
  T.translation() = md - R * ms;
  return T;
}

namespace {

double thresholdFor(const Eigen::Vector3d& p, const RansacOptions& o) {
  return o.inlierThreshold + o.depthCoefficient * p.z() * p.z();
}

/// MSAC score (Torr & Zisserman): Σ min(r²/thr², 1). Unlike a plain inlier count it prefers
/// the hypothesis whose inliers fit tightly, which matters with a generous threshold.
double msacCost(const Pose& T, const std::vector<Eigen::Vector3d>& src,
                const std::vector<Eigen::Vector3d>& dst, const std::vector<double>& thr2,
                size_t* inlierCount) {
  double cost = 0;
  size_t count = 0;
  const Eigen::Matrix3d R = T.linear();
  const Eigen::Vector3d t = T.translation();
  for (size_t i = 0; i < src.size(); ++i) {
    const double r2 = (R * src[i] + t - dst[i]).squaredNorm();
    if (r2 < thr2[i]) {
      cost += r2 / thr2[i];
      ++count;
    } else {
      cost += 1.0;
    }
  }
  *inlierCount = count;
  return cost;
}

size_t countInliers(const Pose& T, const std::vector<Eigen::Vector3d>& src,
                    const std::vector<Eigen::Vector3d>& dst, const std::vector<double>& thr2,
                    std::vector<bool>* mask) {
  size_t count = 0;
  const Eigen::Matrix3d R = T.linear();
  const Eigen::Vector3d t = T.translation();
  for (size_t i = 0; i < src.size(); ++i) {
    const bool in = (R * src[i] + t - dst[i]).squaredNorm() < thr2[i];
    if (mask) (*mask)[i] = in;
    count += in;
  }
  return count;
}

bool degenerateSample(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                      const Eigen::Vector3d& c) {
  // Nearly collinear or coincident points leave the rotation undetermined.
  return (b - a).cross(c - a).norm() < 1e-4;
}

}  // namespace

RansacResult ransacAbsoluteOrientation(const std::vector<Eigen::Vector3d>& src,
                                       const std::vector<Eigen::Vector3d>& dst,
                                       const RansacOptions& o,
                                       const std::vector<double>* refitWeights) {
  RansacResult best;
  const size_t n = src.size();
  best.inliers.assign(n, false);
  if (n < 3 || n < static_cast<size_t>(o.minInliers)) return best;

  std::vector<double> thr2(n);
  for (size_t i = 0; i < n; ++i) thr2[i] = std::pow(thresholdFor(src[i], o), 2);

  std::mt19937 rng(o.seed);
  std::uniform_int_distribution<size_t> pick(0, n - 1);
  size_t bestCount = 0;
  double bestCost = static_cast<double>(n) + 1;
  Pose bestT = Pose::Identity();
  int needed = o.maxIterations;
  int it = 0;
  std::vector<Eigen::Vector3d> s(3), d(3);
  for (; it < needed && it < o.maxIterations; ++it) {
    size_t i0 = pick(rng), i1 = pick(rng), i2 = pick(rng);
    if (i0 == i1 || i0 == i2 || i1 == i2) continue;
    if (degenerateSample(src[i0], src[i1], src[i2]) || degenerateSample(dst[i0], dst[i1], dst[i2]))
      continue;
    s = {src[i0], src[i1], src[i2]};
    d = {dst[i0], dst[i1], dst[i2]};
    const Pose T = fitRigidTransform(s, d);
    size_t c = 0;
    const double cost = msacCost(T, src, dst, thr2, &c);
    if (cost < bestCost) {
      bestCost = cost;
      bestCount = c;
      bestT = T;
      // Adaptive stop: iterations so that an all-inlier sample was drawn with prob. p.
      const double w = static_cast<double>(c) / n;
      const double pAllIn = w * w * w;
      if (pAllIn >= 1.0 - 1e-12) {
        needed = it + 1;
      } else if (pAllIn > 1e-12) {
        const double k = std::log(1.0 - o.confidence) / std::log(1.0 - pAllIn);
        needed = static_cast<int>(std::min<double>(o.maxIterations, std::ceil(k)));
      }
    }
  }
  best.iterations = it;
  if (bestCount < static_cast<size_t>(std::max(3, o.minInliers))) return best;

  // Least-squares refit on all inliers, twice: the refined pose may gain or lose a few
  // borderline pairs.
  std::vector<bool> mask(n);
  Pose T = bestT;
  size_t count = countInliers(T, src, dst, thr2, &mask);
  for (int refine = 0; refine < 2; ++refine) {
    std::vector<Eigen::Vector3d> si, di;
    std::vector<double> wi;
    for (size_t i = 0; i < n; ++i)
      if (mask[i]) {
        si.push_back(src[i]);
        di.push_back(dst[i]);
        if (refitWeights) wi.push_back((*refitWeights)[i]);
      }
    if (si.size() < 3) break;
    const Pose refined = fitRigidTransform(si, di, refitWeights ? &wi : nullptr);
    std::vector<bool> newMask(n);
    const size_t newCount = countInliers(refined, src, dst, thr2, &newMask);
    if (newCount < 3) break;
    T = refined;
    count = newCount;
    mask = newMask;
  }
  if (count < static_cast<size_t>(std::max(3, o.minInliers))) return best;

  double sq = 0;
  for (size_t i = 0; i < n; ++i)
    if (mask[i]) sq += (T * src[i] - dst[i]).squaredNorm();
  best.success = true;
  best.transform = T;
  best.inliers = mask;
  best.inlierCount = count;
  best.rmse = std::sqrt(sq / count);
  return best;
}

}  // namespace slamdunk
