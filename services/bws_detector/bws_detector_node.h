#pragma once
/// @file
/// The bws_detector component: STEREO_IMAGES + MARKERS -> BOOK_CORNER_STEREO
/// (P1 of the right-most book of the upper shelf, in base and grasp, with every
/// region's verdict) and an optional debug picture. Both implementations (GoD,
/// PCL) are this component with another `service.implementation`; they publish
/// the same message on the same channel with their name in `implementation`.
/// A frame is answered with the cart marker from the same frame (MARKERS at its
/// utime): it waits for it, up to pairing.max_pending_frames frames.
/// Frames closer than processing.min_frame_interval_s (message time) to the
/// last one answered are skipped: the shelf is still while BwS is needed, and
/// the coordinator waits for one P1 after it asks.

#include <cstdint>
#include <deque>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "bookgrasp/book_corner_stereo_t.hpp"
#include "bookgrasp/marker_detections_t.hpp"
#include "bookgrasp/stereo_frame_t.hpp"
#include "common/component.h"
#include "common/config.h"
#include "services/bws_detector/bws_pipeline.h"
#include "services/bws_detector/cart_marker_track.h"

namespace bookgrasp {

/// Everything the bws_detector reads from its configuration.
struct BwsDetectorSettings {
  std::string stereo_channel;           ///< channels.stereo (stereo_frame_t)
  std::string markers_channel;          ///< channels.markers (marker_detections_t)
  std::string corner_channel;           ///< channels.corner (book_corner_stereo_t)
  std::string debug_image_channel;      ///< channels.debug_image (image_t, PNG)
  bool publish_debug_image = false;     ///< debug.publish_image
  std::string cart_marker_role;         ///< cart.marker_role: role of the cart marker in MARKERS
  int max_pending_frames = 3;           ///< pairing.max_pending_frames: frames held for their MARKERS (0 = none)
  double min_frame_interval_s = 0;      ///< processing.min_frame_interval_s: frames closer than this in message time
                                        ///< to the last frame answered are skipped (0 = answer every frame)
  bool measure_processing_time = true;  ///< diagnostics.measure_processing_time (wall-time *_ms fields)
  bws::BwsParams params;                ///< algorithm (service.implementation, disparity, god|pcl, selection, cart)

  /// Reads the whole configuration root. Throws ConfigError naming a bad key.
  static BwsDetectorSettings from_config(const Config& root);
};

/// Decodes and checks a stereo frame: both images decodable, 8-bit, same size,
/// the left calibration for that size with finite positive intrinsics, a
/// finite positive baseline, a valid camera pose. Returns "" and fills `input`,
/// or the reason.
std::string stereo_input_from_frame(const stereo_frame_t& frame, bws::StereoInput* input);

/// The BwS detector as a component.
class BwsDetectorNode : public Component {
 public:
  /// Subscribes the stereo and marker channels.
  explicit BwsDetectorNode(const BwsDetectorSettings& settings);

  /// The handler's core, usable without a bus: answers one frame with the cart
  /// marker seen at its utime (else the nearest in time). Returns "" and fills
  /// `out` (and `debug` if not null and the debug image is enabled), or the
  /// reason the frame is rejected.
  std::string process(const stereo_frame_t& frame, book_corner_stereo_t* out, image_t* debug);

  /// Records the cart marker of a MARKERS message (or its absence) at the message's utime;
  /// returns "" or why the message was refused.
  std::string take_markers(const marker_detections_t& msg);

  /// The full result of the last frame process() answered (images, regions, verdicts), for
  /// evaluation and debugging; empty before the first.
  const bws::BwsOutput& last_output() const { return last_; }

  /// Stereo frames skipped since the start because they came within
  /// processing.min_frame_interval_s of the last frame answered.
  int64_t skipped_frames() const { return skipped_frames_; }

 private:
  void on_stereo(const stereo_frame_t& frame);
  void on_markers(const marker_detections_t& msg);
  void answer(const stereo_frame_t& frame);  ///< process() and publish, or reject / wait

  BwsDetectorSettings s_;
  bws::CartMarkerTrack track_;
  std::deque<stereo_frame_t> pending_;  ///< frames waiting for their MARKERS, oldest first
  bws::BwsOutput last_;
  std::optional<int64_t> last_answered_utime_;  ///< utime of the last frame answered (BOOK_CORNER_STEREO sent)
  int64_t skipped_frames_ = 0;
};

}  // namespace bookgrasp
