#pragma once
/// @file
/// Image-based visual servoing on the book corner R (paper Section 2.2): one
/// control step per BwH measurement. Drives R to the target pixel (the pixel at
/// which a point straight ahead of the TCP appears at the requested standoff,
/// HandEyeGeometry::target_pixel, raised by target_above_tcp_m) and the book's image slope to zero, with a
/// TCP twist in the gripper frame (vx = up, vy = right, wz = roll about the
/// approach axis; vz and wx, wy stay zero so the standoff is kept).
///
/// Control law: e = (u - u*, v - v*, slope); de/dt = J u with J from the point
/// interaction matrix at the corner's depth (the corner lies on the plane
/// z_gripper = standoff) mapped through the camera offset, and d(slope)/dt =
/// -w_z(camera). u = -J^-1 diag(gain, gain, slope_gain) e, then saturated.

#include <Eigen/Core>

#include "services/visual_servo/hand_eye_geometry.h"

namespace bookgrasp {

/// Gains, limits and convergence thresholds of the corner servo (from configuration).
struct BookCornerServoParams {
  double gain = 1.5;                 ///< 1/s on the pixel error (exponential decay rate)
  double slope_gain = 1.5;           ///< 1/s on the slope error
  double max_linear_speed = 0.05;    ///< m/s, TCP
  double max_angular_speed = 0.3;    ///< rad/s
  double converged_px = 1.5;         ///< |R - target| below this (pixels) ...
  double converged_slope_rad = 0.01; ///< ... and |slope| below this ...
  int converged_frames = 3;          ///< ... on this many consecutive measurements
  bool align_slope = true;           ///< rotate about the approach axis to zero the slope
  bool compensate_capture_delay = true;  ///< the twist acts on the image's error plus what the TCP's motion since
                                         ///< the image was taken has moved R by (the corner is a fixed point);
                                         ///< false = on the image's error alone, which overshoots with late images
  /// Not in the paper: R is driven to the pixel of the point this far above the TCP (gripper +x) at the standoff,
  /// so the servo ends with the TCP this far below R, and P2 (ServoSession) is that pose raised by it. The hand
  /// camera sits above the TCP: with 0, the nearer the standoff the lower R ends in the image, and at 9 cm it
  /// ended ~26 px above the plates, too little of the fore-edge for BwH. 0 = the paper's (TCP axis through R).
  double target_above_tcp_m = 0.0;
};

/// One control step.
struct CornerServoStep {
  GripperTwist twist = GripperTwist::Zero();  ///< command, gripper frame
  Eigen::Vector2d target_px = Eigen::Vector2d::Zero();  ///< where R is driven
  Eigen::Vector2d error_px = Eigen::Vector2d::Zero();   ///< R - target
  double slope_error_rad = 0;                          ///< slope (target 0)
  bool converged = false;                               ///< thresholds met for converged_frames
};

/// The corner servo's state (consecutive in-tolerance count).
class BookCornerServo {
 public:
  BookCornerServo(const HandEyeGeometry& geometry, const BookCornerServoParams& params);

  /// Restarts the convergence count.
  void reset() { in_tolerance_ = 0; }

  /// One step for corner `r_px` and image slope `slope_rad` (BwH convention:
  /// atan2(dy, dx), image y down) of a book whose front is `standoff_m` ahead
  /// of the TCP.
  /// `moved_since_capture`: the TCP's motion between the image's capture and now (gripper x, y in metres and the
  /// rotation about its z in radians); with compensate_capture_delay the twist acts on the error predicted for
  /// now (first order, through the interaction matrix), while convergence is judged on the image.
  CornerServoStep step(const Eigen::Vector2d& r_px, double slope_rad, double standoff_m,
                       const Eigen::Vector3d& moved_since_capture = Eigen::Vector3d::Zero());

  /// The parameters.
  const BookCornerServoParams& params() const { return p_; }

 private:
  HandEyeGeometry geo_;
  BookCornerServoParams p_;
  int in_tolerance_ = 0;
};

/// Scales `twist` down uniformly so its linear part is at most `max_linear` and
/// its angular part at most `max_angular` (direction kept).
GripperTwist saturate_twist(const GripperTwist& twist, double max_linear, double max_angular);

}  // namespace bookgrasp
