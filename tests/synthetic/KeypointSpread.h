#pragma once
// How much texture a rendered frame offers the tracker: ORB keypoints, and how many cells of a
// 4 x 4 grid over the image hold at least one (the keyframe policy works on such a grid).

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>

namespace slamdunk::test {

struct KeypointSpread {
  size_t keypoints = 0;
  int occupiedCells = 0;  ///< of 16
};

inline KeypointSpread keypointSpread(const cv::Mat& bgr) {
  static const auto orb = cv::ORB::create(20000);  // no cap in practice: count what is there
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  std::vector<cv::KeyPoint> kps;
  orb->detect(grey, kps);
  bool cells[4][4] = {};
  for (const auto& k : kps)
    cells[std::min(3, int(k.pt.y * 4 / grey.rows))][std::min(3, int(k.pt.x * 4 / grey.cols))] =
        true;
  KeypointSpread s;
  s.keypoints = kps.size();
  for (auto& row : cells) s.occupiedCells += int(std::count(row, row + 4, true));
  return s;
}

}  // namespace slamdunk::test
