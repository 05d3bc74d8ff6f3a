#pragma once
// Residual of one point match (paper Eq. 5): e = p_i − T_i⁻¹ T_j p_j, whitened so that the
// squared norm is w eᵀ Ω e (the paper's w ‖e‖² when Ω = I). Poses are a unit quaternion
// (Eigen x,y,z,w order) and a translation, both world ← keyframe optical frame.

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace slamdunk {

class PointMatchResidual {
 public:
  /// sqrtInformation: any S with Sᵀ S = weight · Ω.
  PointMatchResidual(const Eigen::Vector3d& pointI, const Eigen::Vector3d& pointJ,
                     const Eigen::Matrix3d& sqrtInformation)
      : pointI_(pointI), pointJ_(pointJ), sqrtInformation_(sqrtInformation) {}

  template <typename T>
  bool operator()(const T* qI, const T* tI, const T* qJ, const T* tJ, T* residual) const {
    const Eigen::Map<const Eigen::Quaternion<T>> rotI(qI), rotJ(qJ);
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> transI(tI), transJ(tJ);
    // Through the world frame: T_i⁻¹ (T_j p_j) = R_iᵀ (R_j p_j + t_j − t_i).
    const Eigen::Matrix<T, 3, 1> world = rotJ * pointJ_.cast<T>() + transJ;
    const Eigen::Matrix<T, 3, 1> inI = rotI.conjugate() * (world - transI);
    Eigen::Map<Eigen::Matrix<T, 3, 1>> r(residual);
    r = sqrtInformation_.cast<T>() * (pointI_.cast<T>() - inI);
    return true;
  }

  static ceres::CostFunction* create(const Eigen::Vector3d& pointI, const Eigen::Vector3d& pointJ,
                                     double weight, const Eigen::Matrix3d& information) {
    // S = √w Lᵀ with Ω = L Lᵀ gives ‖S e‖² = w eᵀ Ω e.
    const Eigen::Matrix3d L = information.llt().matrixL();
    return new ceres::AutoDiffCostFunction<PointMatchResidual, 3, 4, 3, 4, 3>(
        new PointMatchResidual(pointI, pointJ, std::sqrt(weight) * L.transpose()));
  }

 private:
  Eigen::Vector3d pointI_, pointJ_;
  Eigen::Matrix3d sqrtInformation_;
};

}  // namespace slamdunk
