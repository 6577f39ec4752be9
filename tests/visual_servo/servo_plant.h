#pragma once
/// @file
/// A kinematic plant for the servo cores' unit tests: a TCP moving with the
/// commanded twist (gripper frame, integrated exactly per frame with one frame
/// of delay), a pinhole hand camera at the URDF's hand-eye transform, and a
/// scene in a grasp-like world frame W (X up, Y right, Z into the shelf):
/// a book corner with a rolled top edge, and the black stripe on a board
/// partly hidden by a row of books. The true values (corner, stripe end)
/// are the ground truth the tests measure against.

#include <algorithm>
#include <cmath>
#include <optional>

#include <Eigen/Geometry>

#include "services/visual_servo/hand_eye_geometry.h"
#include "services/visual_servo/stripe_end_servo.h"
#include "services/visual_servo/visual_servo_node.h"

namespace bookgrasp::test {

inline std::string source_dir() { return BOOKGRASP_SOURCE_DIR; }

/// The project's hand-eye geometry: URDF camera pose, sim intrinsics (fovy 58 deg, 640x480).
inline HandEyeGeometry project_geometry() {
  CameraIntrinsics k;
  k.width = 640;
  k.height = 480;
  k.fx = k.fy = 240.0 / std::tan(29.0 * M_PI / 180.0);
  k.cx = 319.5;
  k.cy = 239.5;
  return HandEyeGeometry(k, camera_in_tcp_from_urdf(source_dir() + "/config/robot/lwa3_pg70.urdf", "gripper",
                                                    "hand_camera"));
}

/// Integrates a gripper-frame twist over dt (exact for constant twist via the exponential map).
inline Eigen::Isometry3d integrate(const Eigen::Isometry3d& tcp, const GripperTwist& t, double dt) {
  Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d w = t.tail<3>() * dt;
  if (w.norm() > 1e-12) delta.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  delta.translation() = t.head<3>() * dt;  // small steps: first order in translation is fine at 30 Hz
  return tcp * delta;
}

/// A book corner R at `corner` (W) with its top edge rolled by `roll` about W's Z.
struct CornerScene {
  Eigen::Vector3d corner{0.0, 0.0, 0.3};
  double roll_rad = 0.0;
  double width_m = 0.03;  ///< the top edge's length (the fore-edge's width)
  double neighbour_offset_m = 0.0;  ///< the next fore-edge's right end this far left of R along the edge (0 = none)
  double neighbour_width_m = 0.0;   ///< ... and its width

  /// Pixel of R and image slope (atan2(dy, dx)) seen from `tcp` (W); the top edge's width in image columns (as
  /// page_face_detection measures it) in `width_px` if given.
  bool observe(const HandEyeGeometry& g, const Eigen::Isometry3d& tcp, Eigen::Vector2d* r, double* slope,
               double* width_px = nullptr) const {
    const Eigen::Isometry3d cam = tcp * g.camera_in_gripper();
    // Top edge goes left from R: direction -Y rolled about Z.
    const Eigen::Vector3d dir = Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitZ()) * Eigen::Vector3d(0, -1, 0);
    const Eigen::Vector3d a = cam.inverse() * corner, b = cam.inverse() * (corner + width_m * dir);
    if (a.z() <= 0 || b.z() <= 0) return false;
    const auto& k = g.intrinsics();
    const Eigen::Vector2d pa(k.cx + k.fx * a.x() / a.z(), k.cy + k.fy * a.y() / a.z());
    const Eigen::Vector2d pb(k.cx + k.fx * b.x() / b.z(), k.cy + k.fy * b.y() / b.z());
    if (pa.x() < 0 || pa.y() < 0 || pa.x() > k.width - 1 || pa.y() > k.height - 1) return false;
    *r = pa;
    const Eigen::Vector2d d = pa - pb;  // left-to-right along the edge
    *slope = std::atan2(d.y(), d.x());
    if (width_px) *width_px = std::abs(d.x());
    return true;
  }

  /// The next fore-edge as BwH would give it from `tcp`: how many image columns its upper-right corner lies left of
  /// R, and its width in columns. False when the scene has none.
  bool observe_neighbour(const HandEyeGeometry& g, const Eigen::Isometry3d& tcp, double* offset_px,
                         double* width_px) const {
    if (!(neighbour_width_m > 0)) return false;
    const Eigen::Isometry3d cam = tcp * g.camera_in_gripper();
    const Eigen::Vector3d dir = Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitZ()) * Eigen::Vector3d(0, -1, 0);
    const auto column = [&](double along) {
      const Eigen::Vector3d p = cam.inverse() * (corner + along * dir);
      return g.intrinsics().cx + g.intrinsics().fx * p.x() / p.z();
    };
    *offset_px = column(0.0) - column(neighbour_offset_m);
    *width_px = column(neighbour_offset_m) - column(neighbour_offset_m + neighbour_width_m);
    return true;
  }
};

/// The stripe on the board (Z = board_z) at height X = stripe_x, visible
/// between the side panels except behind the books standing at Z = books_z
/// between Y = books_left and Y = books_right (the true end).
struct StripeScene {
  double board_z = 0.5, books_z = 0.15, stripe_x = 0.0, thickness = 0.02;
  double panel_left = -0.40, panel_right = 0.40;
  double books_left = -0.10, books_right = 0.15;

  /// What an ideal BSwH would report from `tcp` (W): the right-most visible
  /// segment, its end = its left end if inside the image.
  StripeObservation observe(const HandEyeGeometry& g, const Eigen::Isometry3d& tcp) const {
    const Eigen::Isometry3d cam = tcp * g.camera_in_gripper();
    const Eigen::Vector3d c = cam.translation();
    auto shadow = [&](double y_edge) {  // where the ray over a book edge meets the board
      return c.y() + (y_edge - c.y()) * (board_z - c.z()) / (books_z - c.z());
    };
    const auto& k = g.intrinsics();
    auto px = [&](double y) {
      const Eigen::Vector3d p = cam.inverse() * Eigen::Vector3d(stripe_x, y, board_z);
      return Eigen::Vector2d(k.cx + k.fx * p.x() / p.z(), k.cy + k.fy * p.y() / p.z());
    };
    StripeObservation o;
    const double segs[2][2] = {{shadow(books_right), panel_right}, {panel_left, shadow(books_left)}};
    for (const auto& s : segs) {  // right segment first: BSwH prefers the right-most one
      if (s[1] <= s[0]) continue;
      Eigen::Vector2d a = px(s[0]), b = px(s[1]);
      const double x0 = std::max(a.x(), 0.0), x1 = std::min(b.x(), k.width - 1.0);
      if (x1 - x0 < 40) continue;
      o.found = true;
      auto y_at = [&](double x) { return a.y() + (x - a.x()) * (b.y() - a.y()) / (b.x() - a.x()); };
      o.line_start_px = {x0, y_at(x0)};
      o.line_end_px = {x1, y_at(x1)};
      if (a.x() > 3) {
        o.end_found = true;
        o.end_px = a;
      }
      break;
    }
    return o;
  }
};

}  // namespace bookgrasp::test
