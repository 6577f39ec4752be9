#pragma once
/// @file
/// Region-segmentation comparison of Hoover et al., "An experimental
/// comparison of range image segmentation algorithms", IEEE PAMI 18(7), 1996.
///
/// With O(m, n) the pixel overlap of ground-truth region m (P_m pixels) and
/// machine region n (P_n pixels), and a tolerance 0.5 < T <= 1:
///   - correct detection of m by n: O >= T P_m and O >= T P_n;
///   - over-segmentation of m into n_1..n_x (x >= 2): O(m, n_i) >= T P_{n_i} for every i and
///     sum_i O(m, n_i) >= T P_m;
///   - under-segmentation of m_1..m_x (x >= 2) into n: O(m_i, n) >= T P_{m_i} for every i and
///     sum_i O(m_i, n) >= T P_n;
///   - missed: a ground-truth region in none of the above; noise: a machine region in none.
/// Classes are assigned in that order (correct, over, under); a region already
/// classified does not take part in a later class, so every region has exactly one class.
/// Pixels with ground-truth label <= 0 (unknown, shadow) are ignored everywhere:
/// they count in no region's size. Machine label <= 0 is "no region".

#include <vector>

#include <opencv2/core.hpp>

namespace bookgrasp::bws {

/// Result of one comparison.
struct HooverScore {
  /// Number of ground-truth regions (labels > 0 present).
  int gt_regions = 0;
  /// Number of machine regions (labels > 0 present on known ground-truth pixels).
  int machine_regions = 0;
  /// Correct detections (one per ground-truth region detected).
  int correct = 0;
  /// Over-segmentation instances (one per ground-truth region split).
  int over = 0;
  /// Under-segmentation instances (one per machine region covering several ground-truth regions).
  int under = 0;
  /// Ground-truth regions taking part in an under-segmentation.
  int under_gt_regions = 0;
  /// Missed ground-truth regions.
  int missed = 0;
  /// Noise machine regions.
  int noise = 0;
};

/// Compares `machine` against `ground_truth` (both CV_32S, same size) at tolerance T in (0.5, 1].
/// Throws std::invalid_argument on a bad type, size or tolerance.
HooverScore hoover_compare(const cv::Mat& ground_truth, const cv::Mat& machine, double tolerance);

}  // namespace bookgrasp::bws
