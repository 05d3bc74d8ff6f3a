#include "EdgeMomentResidual.h"

#include <Eigen/Eigenvalues>

namespace slamdunk {

EdgeMomentResidual::EdgeMomentResidual(const std::vector<PointMatch>& matches,
                                       const std::vector<double>& weights) {
  // Centring the p_j keeps M well conditioned whatever the distance of the points from the
  // camera.
  double sumW = 0;
  Eigen::Vector3d sumP = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < matches.size(); ++k) {
    sumW += weights[k];
    sumP += weights[k] * matches[k].pointJ;
  }
  centroidJ_ = sumW > 0 ? Eigen::Vector3d(sumP / sumW) : Eigen::Vector3d::Zero();

  Matrix12 M = Matrix12::Zero();
  Vector12 v = Vector12::Zero();
  for (size_t k = 0; k < matches.size(); ++k) {
    const PointMatch& m = matches[k];
    Eigen::Vector4d y;
    y << m.pointJ - centroidJ_, 1.0;
    const Eigen::Matrix3d W = weights[k] * m.information.matrix();
    const Eigen::Vector3d Wp = W * m.pointI;
    for (int c = 0; c < 4; ++c) {
      v.segment<3>(3 * c) += y[c] * Wp;
      for (int d = c; d < 4; ++d) M.block<3, 3>(3 * c, 3 * d) += (y[c] * y[d]) * W;
    }
  }
  M.triangularView<Eigen::StrictlyLower>() = M.transpose();
  // Square root through the eigen-decomposition, not Cholesky: M is singular when the points
  // are coplanar or fewer than four, and then only its range is constrained (v lies in it).
  const Eigen::SelfAdjointEigenSolver<Matrix12> eig(M);
  const Vector12 d = eig.eigenvalues();
  const double floor = 1e-12 * std::max(d.maxCoeff(), 0.0);
  Vector12 sqrtD, invSqrtD;
  for (int n = 0; n < 12; ++n) {
    const bool kept = d[n] > floor && d[n] > 0;
    sqrtD[n] = kept ? std::sqrt(d[n]) : 0.0;
    invSqrtD[n] = kept ? 1.0 / sqrtD[n] : 0.0;
  }
  // S = V √D: Sᵀ = √D Vᵀ and S⁺ v = (√D)⁺ Vᵀ v.
  sqrtMt_ = sqrtD.asDiagonal() * eig.eigenvectors().transpose();
  offset_ = invSqrtD.asDiagonal() * (eig.eigenvectors().transpose() * v);
}

}  // namespace slamdunk
