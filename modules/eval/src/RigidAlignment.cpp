#include <slamdunk/eval/RigidAlignment.h>

#include <Eigen/SVD>

#include <stdexcept>
#include <string>

namespace slamdunk::eval {

Eigen::Isometry3d RigidAlignment::transform() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rotation;
  T.translation() = translation;
  return T;
}

RigidAlignment RigidAlignment::compute(const std::vector<Eigen::Vector3d>& source,
                                       const std::vector<Eigen::Vector3d>& target) {
  if (source.size() != target.size())
    throw std::invalid_argument("RigidAlignment: " + std::to_string(source.size()) +
                                " source points but " + std::to_string(target.size()) +
                                " target points");
  if (source.size() < 3)
    throw std::invalid_argument("RigidAlignment: need at least 3 point pairs, got " +
                                std::to_string(source.size()));

  const double n = static_cast<double>(source.size());
  Eigen::Vector3d sourceMean = Eigen::Vector3d::Zero(), targetMean = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < source.size(); ++i) {
    sourceMean += source[i];
    targetMean += target[i];
  }
  sourceMean /= n;
  targetMean /= n;

  // Cross-covariance of the centred sets; R = argmax trace(R^T W) over rotations.
  Eigen::Matrix3d W = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < source.size(); ++i)
    W += (target[i] - targetMean) * (source[i] - sourceMean).transpose();

  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(W, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d& U = svd.matrixU();
  const Eigen::Matrix3d& V = svd.matrixV();
  // U * V^T may be a reflection (det -1), e.g. for noisy or planar data; flipping the axis of the
  // smallest singular value gives the best proper rotation instead (Umeyama's correction, the
  // same one evaluate_ate.py applies).
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  if (U.determinant() * V.determinant() < 0) S(2, 2) = -1;

  RigidAlignment result;
  result.rotation = U * S * V.transpose();
  result.translation = targetMean - result.rotation * sourceMean;
  return result;
}

}  // namespace slamdunk::eval
