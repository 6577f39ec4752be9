#pragma once
/// @file
/// Tag search over a stream of frames from a fixed camera: the full image now
/// and then, and in between only small regions around the tags of the previous
/// frame. The cart and holder tags stand still in front of the robot's stereo
/// camera, so a region search finds them at a fraction of a full search's cost.
/// Pure: no bus, message time only (the caller's utime), so the same frames in
/// the same order give the same detections.

#include <cstdint>
#include <optional>
#include <set>
#include <vector>

#include <opencv2/core.hpp>

#include "common/config.h"
#include "services/marker_detector/tag_detector.h"

namespace bookgrasp {

/// Settings of the search around the previous frame's tags (`tracking.*`).
struct TagTrackingParams {
  bool enabled = true;                ///< false: every frame is searched whole
  double roi_margin = 1.0;            ///< a region is the tag's bounding box grown on every side by this times its
                                      ///< larger side (room for the tag to move between frames)
  int roi_min_px = 64;                ///< smallest side of a region, pixels
  double full_search_period_s = 1.0;  ///< a whole-image search at least this often in message time: finds tags that
                                      ///< were not in the previous frame (new ones, ones the regions lost)

  /// Reads every field from `cfg` (keys: enabled, roi_margin, roi_min_px,
  /// full_search_period_s). Throws ConfigError naming a bad key.
  static TagTrackingParams from_config(const Config& cfg);
};

/// How one frame was searched.
enum class TagSearchMode {
  kFull,    ///< the whole image
  kRegions  ///< only the regions around the previous frame's tags, and all of them were found again
};

/// The detections of one frame and how they were found.
struct TagSearchResult {
  std::vector<TagDetection> tags;  ///< sorted by id, then centre x, then centre y
  TagSearchMode mode = TagSearchMode::kFull;
  int regions = 0;             ///< regions searched (kRegions), after merging overlapping ones
  bool fallback_used = false;  ///< the blurred second pass ran
};

/// Full-image and region search with a blurred second pass for required tags.
///
/// A frame is searched whole when there is nothing to track, when the last
/// whole search is `full_search_period_s` old or more (message time), when
/// time went backwards or the image size changed, or when a region search
/// lost a tag of the previous frame (then that frame's result is the whole
/// search's). When a tag of `required_ids` is missing after the first pass
/// of a search, a second detector with `fallback_quad_sigma` blur searches
/// the same pixels again and its required tags are added.
class TagSearch {
 public:
  /// Throws std::invalid_argument for a bad detector parameter or a tracking
  /// parameter out of range.
  TagSearch(const TagDetectorParams& detector, double fallback_quad_sigma, const TagTrackingParams& tracking,
            std::set<int> required_ids);

  /// Detects the tags of one CV_8UC1 frame taken at `utime` (microseconds).
  TagSearchResult detect(const cv::Mat& gray, int64_t utime);

  /// Forgets the tracked tags: the next frame is searched whole.
  void reset();

 private:
  std::vector<TagDetection> search(const cv::Mat& gray, const std::set<int>& wanted, bool* fallback_used);
  std::vector<cv::Rect> regions(const cv::Size& image) const;

  TagDetector detector_;
  std::optional<TagDetector> fallback_;
  TagTrackingParams tracking_;
  std::set<int> required_ids_;
  std::vector<TagDetection> previous_;
  std::optional<int64_t> last_utime_;
  std::optional<int64_t> last_full_utime_;
  cv::Size last_size_;
};

}  // namespace bookgrasp
