#pragma once
/// @file
/// Evaluation of BwS on simulated scenes: render the stereo pair of a scene +
/// seed, find the cart marker with the marker detector, run the bws_detector
/// component's frame handler (the same code the process runs), and compare P1
/// with the simulator's ground truth in the true `grasp` frame; then the
/// statistics over many scenes (metrics.json, report.md, a plot like the
/// paper's Figure 12).

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "bookgrasp/ground_truth_t.hpp"
#include "bookgrasp/stereo_frame_t.hpp"
#include "common/sim_render/pinhole_camera.h"

namespace bookgrasp {
class BwsDetectorNode;
class MarkerDetectorNode;
namespace sim_render {
class SimCameraRig;
}
}  // namespace bookgrasp

namespace bookgrasp::eval_bws {

/// Outcome of one scene.
struct SceneResult {
  /// Scene seed.
  uint64_t seed = 0;
  /// The detector published a P1 (found = true).
  bool found = false;
  /// The found P1 is nearer to another upper-shelf book's true P1 than to the right-most book's.
  bool wrong_book = false;
  /// Why the frame failed (marker, rejection, not found, wrong book), empty on success.
  std::string failure;
  /// P1 error (estimate - truth) in the true grasp frame, metres (valid when found).
  Eigen::Vector3d error_grasp = Eigen::Vector3d::Zero();
  /// Owner id (book id or negative code) covering most of the selected region near PI (most of the
  /// pixels near PI when PI moved onto the front layer).
  int selected_owner = -100;
  /// Id of the right-most book (truth).
  int rightmost_id = -1;
  /// Right-most book's thickness, metres (truth), for the report.
  double rightmost_width_m = 0.0;
  /// How far the top's crease moved P1 up its front, metres (NaN: not fitted or not found).
  double top_crease_shift_m = std::numeric_limits<double>::quiet_NaN();
  /// The marker detector found the cart marker.
  bool cart_marker_found = false;
  /// Rotation between the detected cart marker pose (in base) and the true one, degrees (valid when found).
  double cart_marker_angle_deg = 0.0;
  /// Distance between the detected and the true cart marker centre, millimetres (valid when found).
  double cart_marker_position_mm = 0.0;
  /// Stage times from the message, milliseconds.
  double disparity_ms = 0.0;
  /// See disparity_ms.
  double segmentation_ms = 0.0;
  /// See disparity_ms.
  double total_ms = 0.0;
};

/// A rendered scene: the stereo frame message and what the evaluation needs.
struct RenderedScene {
  /// STEREO_IMAGES message (raw RGB8).
  stereo_frame_t frame;
  /// Owner image of the left camera (book id >= 0 or a negative GeomOwner code).
  cv::Mat owner;
  /// The left camera at capture (to draw truth into its image).
  sim_render::PinholeCamera left_camera;
  /// Ground truth at capture.
  ground_truth_t truth;
};

/// Renders the stereo pair of `rig`'s scene at its current state, stamped `utime`.
RenderedScene render_scene(sim_render::SimCameraRig& rig, int64_t utime);

/// Evaluates one rendered scene with the given components (their state:
/// the marker detector's markers are handed to `bws` before the frame).
/// If `overlay` is not null it receives the detector's debug picture (RGB).
SceneResult evaluate_scene(const RenderedScene& scene, uint64_t seed, MarkerDetectorNode& markers, BwsDetectorNode& bws,
                           cv::Mat* overlay);

/// Summary statistics of a sample.
struct Stats {
  /// Mean, median, max; NaN for an empty sample.
  double mean = 0.0, median = 0.0, max = 0.0;
};
/// Stats of `v` (copied).
Stats stats_of(std::vector<double> v);

/// metrics.json text for the results.
std::string metrics_json(const std::vector<SceneResult>& results, const std::string& implementation,
                         const std::string& scene_file, uint64_t first_seed);

/// report.md text (numbers, the command, failures listed).
std::string report_markdown(const std::vector<SceneResult>& results, const std::string& implementation,
                            const std::string& command);

/// A bar plot like the paper's Figure 12: |P1 error| per axis (X, Y, Z, grasp frame, mm)
/// for every scene, failed scenes marked. CV_8UC3 RGB.
cv::Mat figure12_plot(const std::vector<SceneResult>& results, const std::string& title);

}  // namespace bookgrasp::eval_bws
