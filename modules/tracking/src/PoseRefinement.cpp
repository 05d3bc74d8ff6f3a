#include <slamdunk/core/DepthNoiseModel.h>
#include <slamdunk/core/Pose.h>
#include <slamdunk/core/RgbdFrame.h>
#include <slamdunk/tracking/PoseRefinement.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>

namespace slamdunk {

cv::Mat fitPlaneNormals(const cv::Mat& depth, const CameraIntrinsics& K, int radius) {
  cv::Mat normals(depth.size(), CV_32FC3, cv::Scalar::all(0));
  const int window = (2 * radius + 1) * (2 * radius + 1);
  for (int v = 0; v < depth.rows; ++v)
    for (int u = 0; u < depth.cols; ++u) {
      if (!(depth.at<float>(v, u) > 0)) continue;
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      Eigen::Matrix3d sumSq = Eigen::Matrix3d::Zero();
      int n = 0;
      for (int y = std::max(0, v - radius); y <= std::min(depth.rows - 1, v + radius); ++y)
        for (int x = std::max(0, u - radius); x <= std::min(depth.cols - 1, u + radius); ++x) {
          const float z = depth.at<float>(y, x);
          if (!(z > 0)) continue;
          const Eigen::Vector3d p = K.backProject(x, y, z);
          sum += p;
          sumSq += p * p.transpose();
          ++n;
        }
      if (2 * n < window) continue;
      const Eigen::Vector3d mean = sum / n;
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(sumSq / n - mean * mean.transpose());
      // Not a plane: the thinnest spread is not much thinner than the next.
      if (es.eigenvalues()(0) > 0.1 * es.eigenvalues()(1)) continue;
      Eigen::Vector3d normal = es.eigenvectors().col(0);
      if (normal.dot(mean) > 0) normal = -normal;  // towards the camera
      normals.at<cv::Vec3f>(v, u) =
          cv::Vec3f(static_cast<float>(normal.x()), static_cast<float>(normal.y()),
                    static_cast<float>(normal.z()));
    }
  return normals;
}

cv::Mat subsampleDepth(const cv::Mat& depth, int stride) {
  cv::Mat out((depth.rows + stride - 1) / stride, (depth.cols + stride - 1) / stride, CV_32F);
  for (int r = 0; r < out.rows; ++r)
    for (int c = 0; c < out.cols; ++c)
      out.at<float>(r, c) = depth.at<float>(r * stride, c * stride);
  return out;
}

CameraIntrinsics scaleIntrinsics(const CameraIntrinsics& K, int stride) {
  // Subsampled pixel (c, r) is original pixel (c·s, r·s).
  CameraIntrinsics k = K;
  k.fx /= stride;
  k.fy /= stride;
  k.cx /= stride;
  k.cy /= stride;
  k.width = (K.width + stride - 1) / stride;
  k.height = (K.height + stride - 1) / stride;
  k.dist = {0, 0, 0, 0, 0};
  return k;
}

std::vector<Eigen::Vector3d> depthSamples(const RgbdFrame& frame, int stride, double maxDepth) {
  std::vector<Eigen::Vector3d> out;
  const cv::Mat& depth = frame.depth();
  for (int v = stride / 2; v < depth.rows; v += stride)
    for (int u = stride / 2; u < depth.cols; u += stride)
      if (const auto p = frame.backProject(u, v); p && p->z() < maxDepth) out.push_back(*p);
  return out;
}

cv::Mat undistortedDepth(const cv::Mat& depth, const CameraIntrinsics& K, int stride) {
  if (!K.hasDistortion()) return depth;
  cv::Mat out(depth.size(), CV_32F, cv::Scalar(0));
  for (int r = 0; r < out.rows; ++r)
    for (int c = 0; c < out.cols; ++c) {
      const Eigen::Vector2d d = K.distortPixel(c * stride, r * stride);
      out.at<float>(r, c) = interpolatedDepth(depth, d.x() / stride, d.y() / stride);
    }
  return out;
}

namespace {
/// Where a current-frame point lands in the reference depth image.
struct Landing {
  Eigen::Vector3d q;  ///< the point in the reference camera frame
  int u, v;           ///< nearest reference pixel, inside the image
};

std::optional<Landing> landInReference(const Pose& refFromCamera, const Eigen::Vector3d& pc,
                                       const DepthAlignmentTerm& d) {
  const Eigen::Vector3d q = refFromCamera * pc;
  if (q.z() <= 0.1) return std::nullopt;
  const Eigen::Vector2d uv = d.referenceIntrinsics.project(q);
  const int u = static_cast<int>(std::lround(uv.x())), v = static_cast<int>(std::lround(uv.y()));
  if (u < 0 || v < 0 || u >= d.referenceDepth.cols || v >= d.referenceDepth.rows)
    return std::nullopt;
  return Landing{q, u, v};
}
}  // namespace

double depthOverlap(const Pose& T, const DepthAlignmentTerm& d) {
  if (d.framePoints.empty()) return 0;
  const Pose refFromCamera = d.worldFromReference.inverse() * T;
  size_t landed = 0;
  for (const Eigen::Vector3d& pc : d.framePoints) {
    const auto l = landInReference(refFromCamera, pc, d);
    if (!l) continue;
    const float z = d.referenceDepth.at<float>(l->v, l->u);
    if (z > 0 && std::abs(z - l->q.z()) < 2 * d.maxDistance) ++landed;
  }
  return static_cast<double>(landed) / static_cast<double>(d.framePoints.size());
}

std::vector<DepthCorrespondence> depthCorrespondences(const Pose& T, const DepthAlignmentTerm& d) {
  static const DepthNoiseModel noise;
  const Pose refFromWorld = d.worldFromReference.inverse();
  const cv::Mat& D = d.referenceDepth;
  const CameraIntrinsics& K = d.referenceIntrinsics;
  auto pointAt = [&](int u, int v, Eigen::Vector3d& p) {
    if (u < 0 || v < 0 || u >= D.cols || v >= D.rows) return false;
    const float z = D.at<float>(v, u);
    if (!(z > 0)) return false;
    p = K.backProject(u, v, z);
    return true;
  };
  const Pose refFromCamera = refFromWorld * T;
  std::vector<DepthCorrespondence> out;
  out.reserve(d.framePoints.size());
  for (const Eigen::Vector3d& pc : d.framePoints) {
    const auto l = landInReference(refFromCamera, pc, d);
    if (!l) continue;
    const Eigen::Vector3d& q = l->q;
    const int u = l->u, v = l->v;
    // Normals: given (fitted planes), or from neighbouring pixels. One-sided ones from three
    // noisy sensor pixels tilt by tens of degrees and alignment alone then drifts (7-Scenes
    // tracking alone: 0.12 m vs 0.049 m with central differences).
    Eigen::Vector3d p0, pl, pr, pu, pd, n;
    if (!pointAt(u, v, p0)) continue;
    if (!d.referenceNormals.empty()) {
      const cv::Vec3f& f = d.referenceNormals.at<cv::Vec3f>(v, u);
      n = Eigen::Vector3d(f[0], f[1], f[2]);
      if (n.squaredNorm() < 0.5) continue;
    } else {
      if (!pointAt(u + 1, v, pr) || !pointAt(u, v + 1, pd)) continue;
      if (d.centralNormals) {
        if (!pointAt(u - 1, v, pl) || !pointAt(u, v - 1, pu)) continue;
      } else {
        pl = pu = p0;
      }
      n = (pr - pl).cross(pd - pu);
      const double nn = n.norm();
      if (nn < 1e-12) continue;
      n /= nn;
    }
    if (std::abs(n.dot(p0.normalized())) < 0.3) continue;  // grazing surfaces: unreliable depth
    const double r = n.dot(q - p0);
    if (std::abs(r) > d.maxDistance || (q - p0).norm() > 2 * d.maxDistance) continue;
    out.push_back({p0, pc, n, noise.depthSigma(p0.z()) + noise.depthSigma(pc.z()), r});
  }
  return out;
}

namespace {

/// Adds the point-to-plane terms of the depth alignment to the normal equations.
void addDepthTerm(const Pose& T, const DepthAlignmentTerm& d, double huberSigmas,
                  Eigen::Matrix<double, 6, 6>& H, Eigen::Matrix<double, 6, 1>& g) {
  const Eigen::Matrix3d Rrw = d.worldFromReference.linear().transpose();
  for (const DepthCorrespondence& c : depthCorrespondences(T, d)) {
    const Eigen::Vector3d x = T * c.framePoint;  // world
    const Eigen::Vector3d q = d.worldFromReference.inverse() * x;
    const double r = c.normal.dot(q - c.referencePoint);
    const double m = std::abs(r) / c.sigma;
    const double w = d.weight * (m <= huberSigmas ? 1.0 : huberSigmas / m) / (c.sigma * c.sigma);
    // dq/dδ = R_rw [I, -[x]×] for a left perturbation of the world pose.
    Eigen::Matrix<double, 1, 6> J;
    const Eigen::RowVector3d nR = c.normal.transpose() * Rrw;
    J.leftCols<3>() = nR;
    J.rightCols<3>() = -nR * skewSymmetric(x);
    H += w * J.transpose() * J;
    g += w * J.transpose() * r;
  }
}

/// Adds the point pairs' terms to the normal equations of the pose (N = 6) or of the pose and
/// the velocity (N = 12). Fixed sizes and a coefficient-wise product: Eigen's general matrix
/// product (which it picks from 12 x 3 times 3 x 12 on) costs more to set up than to compute.
template <int N>
void addPairTerms(const Pose& T, const std::vector<PosePair>& pairs, const Twist& dv,
                  double huberSigmas, Eigen::Matrix<double, 12, 12>& H,
                  Eigen::Matrix<double, 12, 1>& g) {
  const Eigen::Matrix3d R = T.linear();
  for (const PosePair& p : pairs) {
    const Eigen::Vector3d q = T * (p.source + p.velocityJacobian * dv);
    const Eigen::Vector3d e = q - p.target;
    const Eigen::Matrix3d cov = R * p.sourceCov * R.transpose() + p.targetCov;
    const Eigen::Matrix3d info = cov.inverse();
    const double m2 = e.dot(info * e);  // squared Mahalanobis distance
    const double m = std::sqrt(m2);
    const double w = m <= huberSigmas ? 1.0 : huberSigmas / m;
    // Left perturbation: exp(δ) T p ≈ q + δt + δω × q, so de/dδ = [I, -[q]×]; and the
    // velocity moves the source: de/dν = R dsource/dν.
    Eigen::Matrix<double, 3, N> J;
    J.template leftCols<3>() = Eigen::Matrix3d::Identity();
    J.template middleCols<3>(3) = -skewSymmetric(q);
    if constexpr (N == 12) J.template rightCols<6>() = R * p.velocityJacobian;
    const Eigen::Matrix<double, N, 3> weightedInfo = w * J.transpose() * info;
    H.template topLeftCorner<N, N>() += weightedInfo.lazyProduct(J);
    g.template head<N>() += weightedInfo * e;
  }
}

}  // namespace

Pose refinePose(const Pose& initial, const std::vector<PosePair>& pairs,
                const PoseRefinementOptions& options, const DepthAlignmentTerm* depth,
                FrameVelocity* velocity) {
  Pose T = initial;
  if (velocity) velocity->estimate = velocity->compensated;
  if (pairs.size() < 3 && !depth) return T;
  // The pose's 6 parameters, and the velocity's 6 after them when it is refined too.
  using Matrix12 = Eigen::Matrix<double, 12, 12>;
  using Vector12 = Eigen::Matrix<double, 12, 1>;
  const int n = velocity ? 12 : 6;
  for (int it = 0; it < options.iterations; ++it) {
    Matrix12 H = Matrix12::Zero();
    Vector12 g = Vector12::Zero();
    if (depth) {
      Eigen::Matrix<double, 6, 6> Hd = Eigen::Matrix<double, 6, 6>::Zero();
      Eigen::Matrix<double, 6, 1> gd = Eigen::Matrix<double, 6, 1>::Zero();
      addDepthTerm(T, *depth, options.huberSigmas, Hd, gd);
      H.topLeftCorner<6, 6>() = Hd;
      g.head<6>() = gd;
    }
    if (velocity)
      addPairTerms<12>(T, pairs, Twist(velocity->estimate - velocity->compensated),
                       options.huberSigmas, H, g);
    else
      addPairTerms<6>(T, pairs, Twist::Zero(), options.huberSigmas, H, g);
    if (velocity) {
      const Twist precision = velocity->priorSigma.cwiseInverse().cwiseAbs2();
      H.bottomRightCorner<6, 6>().diagonal() += precision;
      g.tail<6>() += precision.cwiseProduct(velocity->estimate - velocity->prior);
    }
    const Eigen::VectorXd solved = -H.topLeftCorner(n, n).ldlt().solve(g.head(n));
    if (!solved.allFinite()) break;
    const Eigen::Matrix<double, 6, 1> delta = solved.head<6>();
    if (velocity) velocity->estimate += solved.tail<6>();
    Pose step = Pose::Identity();
    const double angle = delta.tail<3>().norm();
    if (angle > 1e-12)
      step.linear() = Eigen::AngleAxisd(angle, delta.tail<3>() / angle).toRotationMatrix();
    step.translation() = delta.head<3>();
    T = step * T;
    if (delta.norm() < 1e-9) break;
  }
  return T;
}

}  // namespace slamdunk
