#pragma once
/// @file
/// Not in the paper: the depth of the right-most book's front from BwS's planar regions just left of PS, for
/// when P1 itself is invalid. An earlier grasp's open left plate pushes the neighbours 6-13 cm back; BwS then
/// often selects another book's front as P1 (or none), while the pushed target's front is still a plane among
/// the regions it publishes. Pure: regions come in the `grasp` frame (X up, Y right, Z into the shelf; metres).

#include <optional>
#include <vector>

#include <Eigen/Core>

namespace bookgrasp {

/// One planar region of the segmentation in the `grasp` frame.
struct FrontPlane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit normal
  double offset = 0;                                   ///< plane: normal . p = offset
  Eigen::Vector3d min = Eigen::Vector3d::Zero();       ///< axis-aligned extent
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
  int pixels = 0;                                      ///< region size in the image
};

/// Which regions count as the target's front, from configuration (arbiter.yaml `stereo_front`).
struct StereoFrontProbe {
  double near_left = 0.002;  ///< the probed Y band starts this far left of PS.y ...
  double far_left = 0.010;   ///< ... and ends this far left (the thinnest books are 10 mm)
  double max_tilt = 0.35;    ///< the region's normal within this of the grasp Z axis, rad (a fore-edge, not a cover)
  double min_top = 0.05;     ///< its top at least this high above the shelf (X), not the shelf's own edge
  double min_z = -0.05;      ///< its depth at the probe within [min_z, max_z] (the upper shelf's books)
  double max_z = 0.20;
};

/// The Z of the largest region (by pixels) that is nearly parallel to the rear board, overlaps the Y band
/// [PS.y - far_left, PS.y - near_left], reaches min_top, and whose plane at the band's middle (and the region's
/// mid height) lies within [min_z, max_z]. Empty when no region qualifies or PS is not finite.
std::optional<double> front_depth_left_of(const std::vector<FrontPlane>& planes, const Eigen::Vector3d& ps,
                                          const StereoFrontProbe& probe);

}  // namespace bookgrasp
