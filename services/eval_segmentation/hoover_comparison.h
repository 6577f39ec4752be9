#pragma once
/// @file
/// Region-segmentation comparison of Hoover et al., "An experimental comparison of range image
/// segmentation algorithms", IEEE PAMI 18(7):673-689, 1996 (the evaluation behind Table 1 of the
/// book-detection paper). A pure library: two label images in, counts and per-region classes out.
///
/// Notation (Hoover's): ground-truth (GT) region R_m with P_m pixels, machine-segmentation (MS) region
/// R_n with P_n pixels, O_mn = number of pixels in both; tolerance 0.5 < T <= 1.
///   - Correct detection of R_m by R_n: O_mn >= T P_m and O_mn >= T P_n.
///   - Over-segmentation of R_m into R_n1..R_nx (2 <= x): O_m,ni >= T P_ni for every i (each MS
///     region lies mostly in R_m) and sum_i O_m,ni >= T P_m (together they cover most of R_m).
///   - Under-segmentation of R_m1..R_mx (2 <= x) into R_n: O_mi,n >= T P_mi for every i and
///     sum_i O_mi,n >= T P_n (symmetric).
///   - Missed: a GT region in no correct detection, over- or under-segmentation.
///   - Noise: an MS region in no correct detection, over- or under-segmentation.
///
/// Uniqueness. With T > 0.5 an MS region can lie >= T inside at most one GT region and vice versa, so
/// (i) each region has at most one correct-detection partner, (ii) the MS regions of different
/// over-segmentations are disjoint, (iii) the GT regions of different under-segmentations are disjoint.
/// The only region that can qualify for two classes is one whose correct-detection pair R_m/R_n also
/// satisfies an over-segmentation of R_m (R_n plus small MS regions in the rest of R_m) or an
/// under-segmentation of R_n (symmetric); Hoover's rule that every region gets one class is applied
/// here as: correct detection wins, and the over/under test is made without the regions already
/// classified correct (so those small MS / GT regions become noise / missed). Over and under cannot
/// both claim a region once correct detections are removed (it would need O > P for T > 0.5).
///
/// Unlabelled pixels. Pixels whose GT label is `no_region` (shadow, no range data, regions too small
/// to be ground truth) count in no region on either side: Hoover's GT images leave such pixels
/// unlabelled and they are not scored. An MS label equal to `no_region` means "pixel in no MS region".
/// A GT region whose pixels are all left unlabelled by the MS is missed.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace bookgrasp::eval_segmentation {

/// Class of one region in a comparison.
enum class HooverClass {
  /// Correct detection (one-to-one).
  kCorrect,
  /// GT region split into several MS regions (GT side) / MS region that is one of the pieces (MS side).
  kOver,
  /// Several GT regions in one MS region (MS side) / GT region that is one of them (GT side).
  kUnder,
  /// GT region in no instance.
  kMissed,
  /// MS region in no instance.
  kNoise,
};

/// Name of a class: "correct", "over", "under", "missed", "noise".
const char* hoover_class_name(HooverClass c);

/// Result of one comparison.
struct HooverResult {
  /// Tolerance T used.
  double tolerance = 0.8;
  /// GT regions (distinct labels != no_region), ascending label order.
  std::vector<int> gt_labels;
  /// Size P_m of every GT region (pixels), same order as gt_labels.
  std::vector<int> gt_sizes;
  /// Class of every GT region, same order as gt_labels.
  std::vector<HooverClass> gt_class;
  /// MS regions (distinct labels != no_region on scored pixels), ascending label order.
  std::vector<int> ms_labels;
  /// Size P_n of every MS region on scored pixels, same order as ms_labels.
  std::vector<int> ms_sizes;
  /// Class of every MS region, same order as ms_labels.
  std::vector<HooverClass> ms_class;
  /// Number of correct detections (= GT regions classified correct = MS regions classified correct).
  int correct = 0;
  /// Number of over-segmentation instances (= GT regions classified over).
  int over = 0;
  /// Number of under-segmentation instances (= MS regions classified under).
  int under = 0;
  /// GT regions taking part in an under-segmentation.
  int under_gt_regions = 0;
  /// MS regions taking part in an over-segmentation.
  int over_ms_regions = 0;
  /// Missed GT regions.
  int missed = 0;
  /// Noise MS regions.
  int noise = 0;

  /// Number of GT regions.
  int num_gt() const { return int(gt_labels.size()); }
  /// Number of MS regions.
  int num_ms() const { return int(ms_labels.size()); }
  /// Class of the GT region with label `label`; throws std::out_of_range if there is none.
  HooverClass gt_class_of(int label) const;
  /// Class of the MS region with label `label`; throws std::out_of_range if there is none.
  HooverClass ms_class_of(int label) const;
};

/// Compares the machine segmentation `machine` with `ground_truth` at tolerance T.
/// Both CV_32SC1 of the same size; `no_region` is the label of unlabelled pixels on both sides.
/// Empty images give a result with no regions. Throws std::invalid_argument naming the problem for
/// another type, different sizes, or T outside (0.5, 1].
HooverResult hoover_compare(const cv::Mat& ground_truth, const cv::Mat& machine, double tolerance, int no_region = 0);

/// Counts of several comparisons added up (a test set), for fractions like Hoover's tables.
struct HooverTotals {
  /// Sum of GT region counts.
  long long gt_regions = 0;
  /// Sum of MS region counts.
  long long ms_regions = 0;
  /// Sums of the instance counts of HooverResult.
  long long correct = 0, over = 0, under = 0, under_gt_regions = 0, over_ms_regions = 0, missed = 0, noise = 0;

  /// Adds one comparison.
  void add(const HooverResult& r);
  /// correct / gt_regions (0 if no GT region).
  double correct_fraction() const;
  /// over / gt_regions (GT regions that were over-segmented).
  double over_fraction() const;
  /// under_gt_regions / gt_regions (GT regions that are part of an under-segmentation).
  double under_fraction() const;
  /// missed / gt_regions.
  double missed_fraction() const;
  /// noise / ms_regions (a fraction of the machine regions, not of the GT regions).
  double noise_fraction() const;
};

}  // namespace bookgrasp::eval_segmentation
