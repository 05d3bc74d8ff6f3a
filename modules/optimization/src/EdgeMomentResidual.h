#pragma once
// All the point matches of one edge as a single 12-component residual. For A = [R | R c + t]
// (R, t = T_i⁻¹ T_j; c = weighted centroid of the p_j) and y = [p_j − c; 1]:
//   Σ_k u_k ‖p_i − T_i⁻¹ T_j p_j‖² = Σ_k u_k ‖p_i − A y_k‖² = ‖A L − C‖²_F + constant,
// with L Lᵀ = Σ u y yᵀ and C = (Σ u p_i yᵀ) L⁻ᵀ. Both forms are linear in A, so they have the same
// minimiser and the same Gauss-Newton steps as the per-match residuals, but cost O(1) per edge
// per iteration instead of O(matches): this is what keeps local problems of ~10⁴ matches fast.

#include <slamdunk/graph/KeyframeGraph.h>

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

namespace slamdunk {

class EdgeMomentResidual {
 public:
  /// weights[k] multiplies the squared error of matches[k] (its weight, or an IRLS weight).
  EdgeMomentResidual(const std::vector<PointMatch>& matches, const std::vector<double>& weights);

  template <typename T>
  bool operator()(const T* qI, const T* tI, const T* qJ, const T* tJ, T* residual) const {
    const Eigen::Matrix<T, 3, 3> rotI =
        Eigen::Map<const Eigen::Quaternion<T>>(qI).toRotationMatrix();
    const Eigen::Matrix<T, 3, 3> rotJ =
        Eigen::Map<const Eigen::Quaternion<T>>(qJ).toRotationMatrix();
    const Eigen::Map<const Eigen::Matrix<T, 3, 1>> transI(tI), transJ(tJ);
    Eigen::Matrix<T, 3, 4> A;
    A.template leftCols<3>() = rotI.transpose() * rotJ;  // relative pose T_i⁻¹ T_j
    A.col(3) =
        A.template leftCols<3>() * centroidJ_.cast<T>() + rotI.transpose() * (transJ - transI);
    Eigen::Map<Eigen::Matrix<T, 3, 4>> r(residual);
    r = A * L_.cast<T>() - C_.cast<T>();
    return true;
  }

  ceres::CostFunction* toCostFunction() const {
    return new ceres::AutoDiffCostFunction<EdgeMomentResidual, 12, 4, 3, 4, 3>(
        new EdgeMomentResidual(*this));
  }

 private:
  Eigen::Vector3d centroidJ_;
  Eigen::Matrix4d L_;
  Eigen::Matrix<double, 3, 4> C_;
};

}  // namespace slamdunk
