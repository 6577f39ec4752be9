#pragma once
/// @file
/// The marker_detector component: STEREO_IMAGES (left image + left
/// calibration; the right image for each tag's depth) -> MARKERS (every tag with its pose in the camera and in
/// `base`, and the role of the cart and holder markers).

#include <map>
#include <string>
#include <vector>

#include "bookgrasp/marker_detections_t.hpp"
#include "bookgrasp/stereo_frame_t.hpp"
#include "common/component.h"
#include "common/config.h"
#include "services/marker_detector/tag_detector.h"
#include "services/marker_detector/tag_pose.h"
#include "services/marker_detector/tag_search.h"
#include "services/marker_detector/tag_stereo_range.h"

namespace bookgrasp {

/// Everything the marker detector reads from its configuration.
struct MarkerDetectorSettings {
  std::string input_channel;            ///< channels.input (stereo_frame_t)
  std::string output_channel;           ///< channels.output (marker_detections_t)
  TagDetectorParams detector;           ///< apriltag.*
  double fallback_quad_sigma = 0;       ///< apriltag.fallback_quad_sigma: a second pass with this blur when a cart or
                                        ///< holder id was not found (<= 0: no second pass)
  TagTrackingParams tracking;           ///< tracking.*: region search around the previous frame's tags
  double default_tag_size_m = 0;        ///< tags.default_size_m: size of tags without a role
  std::vector<int> cart_ids;            ///< tags.cart.ids
  double cart_tag_size_m = 0;           ///< tags.cart.size_m
  std::vector<int> holder_ids;          ///< tags.holder.ids
  double holder_tag_size_m = 0;         ///< tags.holder.size_m
  double cart_max_tilt_rad = 0;         ///< tags.cart.max_tilt_deg: the cart tag is upright within this
  double holder_max_tilt_rad = 0;       ///< tags.holder.max_tilt_deg: the holder tag is upright within this
  double pose_ambiguity_px = 0;         ///< tags.pose_ambiguity_px: IPPE solutions this close in error are both
                                        ///< considered for an upright (cart, holder) tag
  bool report_unassigned = true;        ///< tags.report_unassigned: publish tags whose id has no role
  TagStereoRangeParams stereo_range;    ///< stereo_range.*: each tag's depth from its disparity in the right image
  bool measure_processing_time = true;  ///< diagnostics.measure_processing_time (wall time in processing_ms)

  /// Reads the whole configuration root (channels, apriltag, tags,
  /// diagnostics). Throws ConfigError naming a bad key (also for an id that
  /// is both a cart and a holder id).
  static MarkerDetectorSettings from_config(const Config& root);
};

/// Checks a calibration and returns its intrinsics; on a problem returns
/// false and says what is wrong in `reason` (NaN, non-positive focal length,
/// unknown distortion model, wrong coefficient count, size mismatch).
bool intrinsics_from_calibration(const camera_calibration_t& calib, int image_width, int image_height,
                                 TagCameraIntrinsics* intrinsics, std::string* reason);

/// The AprilTag marker detector as a component.
class MarkerDetectorNode : public Component {
 public:
  /// Subscribes settings.input_channel. Throws std::invalid_argument for bad detector parameters.
  explicit MarkerDetectorNode(const MarkerDetectorSettings& settings);

  /// Detects markers in one stereo frame (left image); the core of the
  /// handler, usable without a bus. Frames are expected in message-time
  /// order: between whole-image searches only the regions around the
  /// previous frame's tags are searched (TagSearch). Returns false and a
  /// reason for a frame that cannot be processed.
  bool process(const stereo_frame_t& frame, marker_detections_t* out, std::string* reason);

 private:
  void on_stereo(const stereo_frame_t& frame);
  /// Slides `pose` to the tag's stereo depth (the right image decoded into `right_gray` once per frame); on any
  /// problem keeps the monocular pose and says why in the status.
  void range_in_stereo(const stereo_frame_t& frame, const cv::Mat& left_gray, const TagCameraIntrinsics& k,
                       const TagDetection& d, const std::string& role, cv::Mat* right_gray, TagPose* pose);

  MarkerDetectorSettings settings_;
  std::map<int, std::string> role_of_id_;
  TagSearch search_;  ///< whole-image and region search, with the blurred second pass for cart and holder tags
};

}  // namespace bookgrasp
