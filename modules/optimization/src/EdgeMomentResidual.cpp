#include "EdgeMomentResidual.h"

#include <Eigen/Eigenvalues>

namespace slamdunk {

EdgeMomentResidual::EdgeMomentResidual(const std::vector<PointMatch>& matches,
                                       const std::vector<double>& weights) {
  // Centring the p_j keeps Σ u y yᵀ well conditioned (block-diagonal) whatever the distance
  // of the points from the camera.
  double sumW = 0;
  Eigen::Vector3d sumP = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < matches.size(); ++k) {
    sumW += weights[k];
    sumP += weights[k] * matches[k].pointJ;
  }
  centroidJ_ = sumW > 0 ? Eigen::Vector3d(sumP / sumW) : Eigen::Vector3d::Zero();

  Eigen::Matrix4d Syy = Eigen::Matrix4d::Zero();
  Eigen::Matrix<double, 3, 4> Spy = Eigen::Matrix<double, 3, 4>::Zero();
  for (size_t k = 0; k < matches.size(); ++k) {
    Eigen::Vector4d y;
    y << matches[k].pointJ - centroidJ_, 1.0;
    Syy.noalias() += weights[k] * y * y.transpose();
    Spy.noalias() += weights[k] * matches[k].pointI * y.transpose();
  }
  // Square root through the eigen-decomposition, not Cholesky: Syy is singular when the points
  // are coplanar or fewer than four, and then only its range is constrained (Spy lies in it).
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(Syy);
  const Eigen::Vector4d d = eig.eigenvalues();
  const double floor = 1e-12 * std::max(d.maxCoeff(), 0.0);
  Eigen::Vector4d sqrtD, invSqrtD;
  for (int n = 0; n < 4; ++n) {
    const bool kept = d[n] > floor && d[n] > 0;
    sqrtD[n] = kept ? std::sqrt(d[n]) : 0.0;
    invSqrtD[n] = kept ? 1.0 / sqrtD[n] : 0.0;
  }
  L_ = eig.eigenvectors() * sqrtD.asDiagonal();
  C_ = Spy * eig.eigenvectors() * invSqrtD.asDiagonal();
}

}  // namespace slamdunk
