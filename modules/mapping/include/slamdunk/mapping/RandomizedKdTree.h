#pragma once
// Approximate nearest neighbours of float descriptors in Euclidean distance: one randomized k-d
// tree searched best bin first (Beis & Lowe 1997; Silpa-Anan & Hartley 2008).
//
// Each node splits its rows at the mean of one of the dimensions where they vary most, drawn at
// random among the first few; a search descends to the query's leaf, then to the leaves nearest
// the query's side of each split passed, until it has compared a given number of rows. The pool
// builds one per window (tens of thousands of rows, off the tracking thread) and searches it
// from the tracking thread's search threads: building and searching allocate nothing shared,
// and the same rows and seed give the same tree and the same answers.

#include <opencv2/core/mat.hpp>

#include <cstdint>
#include <vector>

namespace slamdunk {

class RandomizedKdTree {
 public:
  /// Indexes the rows of `rows` (CV_32F, one descriptor per row; copied). `seed` draws the splits.
  RandomizedKdTree(const cv::Mat& rows, uint32_t seed);

  size_t size() const { return rowOf_.size(); }

  /// The k nearest rows of `query` (cols() floats) among those compared, at least `checks` of
  /// them (all, for a tree that holds fewer): their row numbers in `indices` and Euclidean
  /// distances (not squared) in `distances`, nearest first. Returns how many it found (k, or
  /// fewer when the tree holds fewer rows). Thread-safe.
  int knn(const float* query, int k, int checks, int* indices, float* distances) const;

 private:
  struct Node {
    int dim = -1;  ///< -1: a leaf, whose rows are [begin, end) in leaf order
    float split = 0;
    int below = -1, above = -1;  ///< children: values < split, and the others
    int begin = 0, end = 0;
  };
  int build(std::vector<int>& order, int begin, int end, const cv::Mat& rows, uint32_t& random);
  const float* point(int i) const { return points_.data() + size_t(i) * cols_; }

  int cols_ = 0;
  std::vector<Node> nodes_;
  std::vector<float> points_;  ///< the rows in leaf order
  std::vector<int> rowOf_;     ///< the row each point came from
};

}  // namespace slamdunk
