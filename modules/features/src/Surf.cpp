#include "slamdunk/features/Surf.h"

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

#include "SurfDescriptor.h"
#include "SurfHessian.h"
#include "SurfIntegral.h"

namespace slamdunk {
namespace {

// Keypoints per parallel task when describing: a few microseconds each.
constexpr int kKeypointsPerTask = 16;

/// 8-bit single-channel view or copy of the input; throws cv::Exception for what SURF cannot use.
cv::Mat toGray8(const cv::Mat& image) {
  const int depth = image.depth();
  const int channels = image.channels();
  if (depth != CV_8U && depth != CV_16U) {
    CV_Error(cv::Error::StsUnsupportedFormat,
             "slamdunk::Surf: image depth must be 8-bit or 16-bit unsigned, got " +
                 cv::typeToString(image.type()));
  }
  if (channels != 1 && channels != 3 && channels != 4) {
    CV_Error(cv::Error::StsUnsupportedFormat,
             "slamdunk::Surf: image must have 1, 3 (BGR) or 4 (BGRA) channels, got " +
                 std::to_string(channels));
  }
  cv::Mat gray = image;
  if (channels == 3) cv::cvtColor(image, gray, cv::COLOR_BGR2GRAY);
  if (channels == 4) cv::cvtColor(image, gray, cv::COLOR_BGRA2GRAY);
  if (depth == CV_16U) gray.convertTo(gray, CV_8U, 1.0 / 257.0);  // 0..65535 -> 0..255
  return gray;
}

cv::Mat checkedMask(const cv::Mat& mask, const cv::Size& imageSize) {
  if (mask.empty()) return mask;
  if (mask.type() != CV_8UC1 || mask.size() != imageSize) {
    CV_Error(cv::Error::StsBadArg,
             "slamdunk::Surf: mask must be empty or CV_8UC1 of the image size");
  }
  return mask;
}

/// Scratch memory reused by successive calls on the same thread. Multi-megabyte blocks are
/// returned to the OS when freed, and faulting their pages back in on every frame would cost
/// about as much as the filtering itself (~1400 page faults per VGA frame).
struct Workspace {
  cv::Mat integral;
  std::vector<cv::Mat> determinants;
};

Workspace& threadWorkspace() {
  thread_local Workspace workspace;
  return workspace;
}

/// compute() contract of cv::Feature2D: keypoints that cannot be described are removed.
void removeUndescribable(std::vector<cv::KeyPoint>& keypoints, const cv::Size& imageSize) {
  const auto bad = [&](const cv::KeyPoint& kp) {
    return !(kp.size > 0.f) || !(kp.pt.x >= 0.f && kp.pt.x <= imageSize.width - 1.f) ||
           !(kp.pt.y >= 0.f && kp.pt.y <= imageSize.height - 1.f);
  };
  keypoints.erase(std::remove_if(keypoints.begin(), keypoints.end(), bad), keypoints.end());
}

/// Sets each keypoint's angle (angleOf) and writes its descriptor row.
template <class AngleOf>
void describe(const surf::IntegralImage& integral, bool extended,
              std::vector<cv::KeyPoint>& keypoints, cv::OutputArray descriptors,
              const AngleOf& angleOf) {
  const bool wantDescriptors = descriptors.needed();
  const int n = static_cast<int>(keypoints.size());
  cv::Mat desc;
  if (wantDescriptors && n == 0) descriptors.release();
  if (wantDescriptors && n > 0) {
    descriptors.create(n, extended ? 128 : 64, CV_32F);
    desc = descriptors.getMat();
  }
  // Every keypoint writes only its own angle and descriptor row: deterministic in parallel.
  const double stripes = std::ceil(n / static_cast<double>(kKeypointsPerTask));
  cv::parallel_for_(
      cv::Range(0, n),
      [&](const cv::Range& r) {
        for (int i = r.start; i < r.end; ++i) {
          cv::KeyPoint& kp = keypoints[i];
          kp.angle = angleOf(kp);
          if (!desc.empty()) {
            surf::computeDescriptor(integral, kp, extended, desc.ptr<float>(i));
          }
        }
      },
      stripes);
}

}  // namespace

Surf::Surf(const Params& params) : params_(params) {
  CV_Assert(params.nOctaves >= 1 && params.nOctaves <= 16);
  CV_Assert(params.nOctaveLayers >= 1 && params.nOctaveLayers <= 16);
  CV_Assert(params.hessianThreshold >= 0.0 && params.maxKeypoints >= 0);
  CV_Assert(params.maxInterpolationOffset > 0.0);
}

cv::Ptr<Surf> Surf::create(const Params& params) { return cv::makePtr<Surf>(params); }

void Surf::detectAndCompute(cv::InputArray image, cv::InputArray mask,
                            std::vector<cv::KeyPoint>& keypoints, cv::OutputArray descriptors,
                            bool useProvidedKeypoints) {
  if (image.empty()) {
    keypoints.clear();
    if (descriptors.needed()) descriptors.release();
    return;
  }
  const cv::Mat gray = toGray8(image.getMat());
  const cv::Mat maskMat = checkedMask(mask.getMat(), gray.size());
  Workspace& workspace = threadWorkspace();
  const surf::IntegralImage integral(gray, workspace.integral);

  if (useProvidedKeypoints) {
    removeUndescribable(keypoints, gray.size());
  } else {
    surf::HessianParams hessian;
    hessian.threshold = static_cast<float>(params_.hessianThreshold);
    hessian.nOctaves = params_.nOctaves;
    hessian.nOctaveLayers = params_.nOctaveLayers;
    hessian.maxOffset = params_.maxInterpolationOffset;
    keypoints = surf::detectFastHessian(integral, hessian, maskMat, workspace.determinants);
    if (params_.maxKeypoints > 0 && static_cast<int>(keypoints.size()) > params_.maxKeypoints) {
      keypoints.resize(params_.maxKeypoints);
    }
  }

  describe(integral, params_.extended, keypoints, descriptors,
           [this, &integral](const cv::KeyPoint& kp) {
             return params_.upright ? -1.f : surf::dominantOrientation(integral, kp);
           });
}

void Surf::computeTurned(cv::InputArray image, std::vector<cv::KeyPoint>& keypoints,
                         cv::OutputArray descriptors, float angleDegrees) {
  CV_Assert(!image.empty());
  const cv::Mat gray = toGray8(image.getMat());
  removeUndescribable(keypoints, gray.size());
  const surf::IntegralImage integral(gray, threadWorkspace().integral);
  const float angle = turnedAngle(angleDegrees);
  describe(integral, params_.extended, keypoints, descriptors,
           [angle](const cv::KeyPoint&) { return angle; });
}

float Surf::turnedAngle(float angleDegrees) {
  const float angle = std::fmod(angleDegrees, 360.f);
  return angle < 0.f ? angle + 360.f : angle;
}

}  // namespace slamdunk
