#pragma once
// Robust loss for a residual already scaled by √w: ρ_w(s) = w ρ(s / w). Since s = w ‖e‖², this
// is w ρ(‖e‖²): the loss bends at the same distance in metres whatever the match's weight, and
// each match still contributes in proportion to its weight (the paper's cost when ρ(s) = s).

#include <ceres/loss_function.h>

namespace slamdunk {

class WeightedRobustLoss : public ceres::LossFunction {
 public:
  /// rho is shared and not owned; weight > 0.
  WeightedRobustLoss(const ceres::LossFunction* rho, double weight) : rho_(rho), weight_(weight) {}

  void Evaluate(double s, double out[3]) const override {
    rho_->Evaluate(s / weight_, out);
    out[0] *= weight_;  // ρ_w = w ρ(s/w); ρ_w' = ρ'(s/w) unchanged; ρ_w'' = ρ''(s/w) / w
    out[2] /= weight_;
  }

 private:
  const ceres::LossFunction* rho_;
  double weight_;
};

}  // namespace slamdunk
