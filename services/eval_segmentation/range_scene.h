#pragma once
/// @file
/// Range images with ground-truth segments from the simulator: the stereo camera's view of a seeded
/// library scene (common/scene + common/sim_render), rendered with exact depth and per-pixel geom ids,
/// and a ground-truth label image with one region per visible surface:
///   - one region per visible face of every box geom (book front = the fore-edge plate's outer face,
///     book sides and top, shelf boards, rear board, side panels, holder plates, screen...), per cap
///     and per mantle of a cylinder, per sphere, per plane geom (floor), per mesh geom (robot links);
///   - faces of different geoms that lie in one plane (normals within `coplanar_max_angle_deg`,
///     offsets within `coplanar_max_offset_m`) and touch in the image are one surface (a marker or
///     the stripe on the rear board, a book's fore-edge plate beside its cover): no range data can
///     separate them;
///   - pixels of no geom or beyond `max_depth_m`, regions smaller than `min_region_px` and the
///     left `left_margin_px` columns (where block matching has no disparity) are unlabelled (0).
/// Optionally (`curved_objects`, off by default; config/scenes/default.yaml and common/scene are not
/// changed) a cup (cylinder) and a ball (sphere) with a speckled texture are added as static geoms on
/// the upper shelf beside the books, where the row of books leaves room.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "bookgrasp/ground_truth_t.hpp"
#include "common/sim_render/pinhole_camera.h"

namespace bookgrasp::eval_segmentation {

/// How a range scene is made.
struct RangeSceneOptions {
  /// Scene YAML (absolute, or relative to the working directory).
  std::string scene_file = "config/scenes/default.yaml";
  /// Scene seed.
  uint64_t seed = 1;
  /// Add a cup and a ball on the upper shelf (curved surfaces).
  bool curved_objects = false;
  /// Ground-truth regions with fewer pixels are unlabelled.
  int min_region_px = 100;
  /// Coplanar faces of different geoms: max angle between normals, degrees.
  double coplanar_max_angle_deg = 2.0;
  /// Coplanar faces of different geoms: max plane offset difference, metres.
  double coplanar_max_offset_m = 0.002;
  /// Pixels farther than this (metres along the optical axis) are unlabelled (room walls).
  double max_depth_m = 3.0;
  /// Columns 0..left_margin_px-1 are unlabelled.
  int left_margin_px = 0;
  /// Message time of the capture (seeds the sensor noise).
  int64_t utime = 1000000;
};

/// One ground-truth region.
struct GtRegion {
  /// Label in RangeScene::gt_labels (1..).
  int label = 0;
  /// Pixels.
  int pixel_count = 0;
  /// Name of its largest face: "<geom name>:<face>" with face +x/-x/+y/-y/+z/-z (box, geom axes),
  /// cap+/cap-/mantle (cylinder), sphere, plane, mesh.
  std::string name;
  /// Book id (>= 0) or scene::GeomOwner code of that face's geom.
  int owner = 0;
  /// True for a planar surface, false for curved ones (cylinder mantle, sphere, mesh).
  bool planar = true;
};

/// A rendered scene with ground truth.
struct RangeScene {
  /// Left and right cameras (calibration and pose in base).
  sim_render::PinholeCamera left_camera, right_camera;
  /// Stereo baseline, metres.
  double baseline_m = 0.0;
  /// Left and right colour images after the cameras' sensor model (CV_8UC3 RGB).
  cv::Mat left_rgb, right_rgb;
  /// Exact depth of the left camera (CV_32F metres along the optical axis, NaN = nothing).
  cv::Mat depth;
  /// Ground-truth labels (CV_32S, 0 = unlabelled), regions described in `regions` (regions[i].label = i + 1).
  cv::Mat gt_labels;
  /// See gt_labels.
  std::vector<GtRegion> regions;
  /// Final label of every visible face "<geom name>:<face>" (also faces that were dropped: label 0).
  std::map<std::string, int> face_label;
  /// Simulator ground truth (books, right-most book, cart).
  ground_truth_t truth;
  /// Curved objects placed (0..2).
  int curved_objects_placed = 0;

  /// Label of the right-most upper-shelf book's front (fore-edge) surface, 0 if not a GT region.
  int rightmost_front_label() const;
};

/// Renders the scene of `options` and builds its ground truth. Throws std::runtime_error (scene file,
/// MuJoCo, rendering problems) or std::invalid_argument (bad options) naming the problem.
RangeScene render_range_scene(const RangeSceneOptions& options);

/// A colour picture of a label image (CV_8UC3 RGB): each label a fixed pseudo-random colour, 0 black.
cv::Mat colorize_labels(const cv::Mat& labels);

}  // namespace bookgrasp::eval_segmentation
