#pragma once
// All the point matches of one edge as a single 12-component residual. With the relative pose
// as A = [R | R c + t] (R, t = T_i⁻¹ T_j; c = weighted centroid of the p_j), y = [p_j − c; 1] and
// a = vec(A), each match's error is e = p_i − A y = p_i − (yᵀ ⊗ I) a, so
//   Σ_k u_k e_kᵀ Ω_k e_k = aᵀ M a − 2 aᵀ v + const,  M = Σ u (y yᵀ ⊗ Ω),  v = Σ u (y ⊗ Ω p_i).
// With M = S Sᵀ the residual Sᵀ a − S⁺ v has that squared norm up to a constant: the same
// minimiser and Gauss-Newton steps as the per-match residuals, at O(1) cost per edge per
// iteration instead of O(matches). This is what keeps local problems of ~10⁴ matches fast.

#include <slamdunk/graph/KeyframeGraph.h>

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

namespace slamdunk {

class EdgeMomentResidual {
 public:
  using Matrix12 = Eigen::Matrix<double, 12, 12>;
  using Vector12 = Eigen::Matrix<double, 12, 1>;

  /// weights[k] multiplies the cost of matches[k] (its weight, or an IRLS weight).
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
    const Eigen::Map<const Eigen::Matrix<T, 12, 1>> a(A.data());  // column-major vec(A)
    Eigen::Map<Eigen::Matrix<T, 12, 1>> r(residual);
    r = sqrtMt_.cast<T>() * a - offset_.cast<T>();
    return true;
  }

  ceres::CostFunction* toCostFunction() const {
    return new ceres::AutoDiffCostFunction<EdgeMomentResidual, 12, 4, 3, 4, 3>(
        new EdgeMomentResidual(*this));
  }

 private:
  Eigen::Vector3d centroidJ_;
  Matrix12 sqrtMt_;  ///< Sᵀ
  Vector12 offset_;  ///< S⁺ v
};

}  // namespace slamdunk
