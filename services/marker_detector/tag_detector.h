#pragma once
/// @file
/// AprilTag 3 detection on a grey image: a thin, owning wrapper around the
/// C library, with plain inputs (cv::Mat) and plain outputs (TagDetection).

#include <array>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "common/config.h"

namespace bookgrasp {

/// Settings of the AprilTag detector (see apriltag.h for their meaning).
struct TagDetectorParams {
  std::string family = "tag36h11";   ///< tag family: tag36h11, tag25h9 or tag16h5
  double quad_decimate = 2.0;        ///< quad detection on an image decimated by this factor (1 = full size)
  double quad_sigma = 0.0;           ///< Gaussian blur sigma applied before quad detection (0 = none)
  bool refine_edges = true;          ///< snap quad edges to strong image gradients
  double decode_sharpening = 0.25;   ///< sharpening of the decoded image
  int threads = 1;                   ///< worker threads of the detector
  int max_hamming = 2;               ///< bit errors corrected (0..2); detections with more are never reported
  double min_decision_margin = 0.0;  ///< detections with a smaller decision margin are dropped

  /// Reads every field from `cfg` (keys: family, quad_decimate, quad_sigma,
  /// refine_edges, decode_sharpening, threads, max_hamming,
  /// min_decision_margin). Throws ConfigError naming a bad key.
  static TagDetectorParams from_config(const Config& cfg);
};

/// One tag found in an image, in the detector's conventions.
struct TagDetection {
  std::string family;            ///< family name, e.g. "tag36h11"
  int id = -1;                   ///< decoded id
  int hamming = 0;               ///< bits corrected
  double decision_margin = 0.0;  ///< mean distance of data bits from the threshold (higher = better)
  /// Image corners (x, y) in pixels, AprilTag order: counter-clockwise as seen
  /// in the image, starting at the corner of tag coordinates (-1, +1), i.e.
  /// for an upright tag: bottom-left, bottom-right, top-right, top-left.
  std::array<cv::Point2d, 4> corners;
  cv::Point2d center;  ///< image of the tag centre, pixels
};

/// Sorts detections by id, then centre x, then centre y (the order detect()
/// returns them in).
void sort_tag_detections(std::vector<TagDetection>* tags);

/// The AprilTag detector. Not copyable (it owns the C detector and family);
/// detect() is not re-entrant: use one instance per thread.
class TagDetector {
 public:
  /// Creates the detector. Throws std::invalid_argument for a bad parameter
  /// (unknown family, decimate < 1, threads < 1, max_hamming outside 0..2).
  explicit TagDetector(const TagDetectorParams& params);
  ~TagDetector();
  TagDetector(TagDetector&&) noexcept;
  TagDetector& operator=(TagDetector&&) noexcept;
  TagDetector(const TagDetector&) = delete;
  TagDetector& operator=(const TagDetector&) = delete;

  /// Detects tags in a CV_8UC1 image (throws std::invalid_argument for any
  /// other type or an empty image). Results are sorted by id, then by centre
  /// x, then centre y, so the output order does not depend on threads.
  std::vector<TagDetection> detect(const cv::Mat& gray);

  /// The parameters it was made with.
  const TagDetectorParams& params() const { return params_; }

 private:
  struct Impl;
  TagDetectorParams params_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace bookgrasp
