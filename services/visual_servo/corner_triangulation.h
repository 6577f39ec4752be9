#pragma once
/// @file
/// The book corner R located in 3D from the hand camera's views of it while the corner servo moves the
/// camera (motion stereo; not in the paper, where the hand camera gives no depth). Each BwH measurement is a
/// viewing ray from the camera's pose at capture; the corner is the point nearest to all rays in the least-
/// squares sense. Its depth is what the servo otherwise assumes (the standoff) and GP.z otherwise takes from
/// BwS, which is wrong for a book pushed back by an earlier grasp. Pure Eigen; no LCM.

#include <optional>
#include <vector>

#include <Eigen/Geometry>

#include "services/visual_servo/hand_eye_geometry.h"

namespace bookgrasp {

/// One view of the corner: the camera's optical frame in `base` at capture and R's pixel.
struct CornerSighting {
  Eigen::Isometry3d camera_in_base = Eigen::Isometry3d::Identity();
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();
};

/// Acceptance limits of a triangulation (from configuration).
struct CornerTriangulationParams {
  double min_baseline_m = 0.015;  ///< camera centres must span at least this (the depth's error grows as 1/baseline)
  double max_rms_px = 2.0;        ///< RMS error of the agreeing views at most this (pixels)
  int min_sightings = 4;          ///< at least this many views
};

/// A triangulated corner.
struct TriangulatedCorner {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();  ///< in `base`
  double baseline_m = 0;                            ///< largest distance between two camera centres
  double rms_px = 0;                                ///< RMS of the views' errors (pixels)
  int sightings = 0;                                ///< views used
  /// Indices into the sightings of every view whose ray passes within 2 x max_rms_px of `point` (also those
  /// left out of the search when there were more than it takes): the views that saw R at this corner.
  std::vector<size_t> agreeing;
};

/// The point nearest to the viewing rays of the largest set of sightings that agree (each within 2 x max_rms_px
/// of the point of some pair of them: R detected on another edge on the way is left out). A view's error is the
/// angle between its ray and the direction to the point, times fx (the reprojection error for small angles). Returns
/// nothing, with `why` set, when there are fewer than min_sightings views, their centres span less than
/// min_baseline_m, the rays are (nearly) parallel, the point lies behind a camera, or the agreeing views are fewer than
/// min_sightings, span less than min_baseline_m or have an RMS error above max_rms_px (R was not one fixed point).
std::optional<TriangulatedCorner> triangulate_corner(const std::vector<CornerSighting>& sightings,
                                                     const CameraIntrinsics& intrinsics,
                                                     const CornerTriangulationParams& params, std::string* why);

}  // namespace bookgrasp
