#pragma once
/// @file
/// The arbiter process (paper Section 3): fuses P1 (BwS), PS (BSwH or the
/// previous grasp) and P2 (BwH servoing) with the combination strategy in the
/// `grasp` frame and publishes every decision on GRASP_POINT.
///
/// Protocol (no request message; decisions follow the bus, see docs/ARCHITECTURE.md):
/// - The grasp frame is the cart frame seen from the robot: origin at the upper
///   shelf's front edge centre, placed from the cart marker (MARKERS, role
///   `cart.marker_role`) by `cart.grasp_origin_in_marker_m`; Z = the marker's
///   into-board axis made horizontal, X = base up, Y = right.
/// - P1 comes from BOOK_CORNER_STEREO messages of the followed implementation
///   (`follow.implementation`, changed by DETECTOR_SWITCH). An *attempt* (one
///   try at one book) opens at start and after every GRASP or NO_GRASP decision
///   and every SERVO_REQUEST CANCEL; its P1 is frozen at the attempt's first
///   non-cancel SERVO_REQUEST (the latest P1 before it). Only frames taken after
///   the arm had been still for `p1.arm_still_s` count (ARM_STATE not EXECUTING
///   and no joint faster than `p1.arm_still_joint_speed`): a frame taken while
///   the arm moves in front of the shelf shows the arm, not the books; such a
///   frame neither replaces the latest P1 nor makes a P1 check.
/// - GRASP_POINT.reason starts with the outcome word:
///   `P1_VALID` / `P1_INVALID` (P1 check: on every followed BOOK_CORNER_STEREO
///   while P1 is not frozen and PS is known, and when a STRIPE_END servo
///   converges; gp_grasp = where BwH starts (P1 or PS), gp_base = that point
///   with the grasp orientation; valid = false, p1_used = P1 valid),
///   `NEED_PS` (a P1 arrived but no PS is known: run BSwH),
///   `GRASP` (a BOOK_CORNER servo converged and GP is valid: valid = true),
///   `NEXT_REGION rank N` (re-run BwH on region N from the right),
///   `NO_GRASP` (no grasp point: the BwH servo failed, no region left, no frame),
///   `BOOK_WIDTH` (after a GRASP: the gripper closed on the book; BW measured
///   from the plates, PS updated to PS.y = GP.y - BW; valid = width admissible).

#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "bookgrasp/arm_state_t.hpp"
#include "bookgrasp/book_corner_stereo_t.hpp"
#include "bookgrasp/detector_switch_t.hpp"
#include "bookgrasp/grasp_point_t.hpp"
#include "bookgrasp/marker_detections_t.hpp"
#include "bookgrasp/servo_request_t.hpp"
#include "bookgrasp/servo_status_t.hpp"
#include "common/component.h"
#include "common/config.h"
#include "services/arbiter/combination_strategy.h"
#include "services/arbiter/stereo_front_depth.h"

namespace bookgrasp {

/// Everything the arbiter node reads from its configuration.
struct ArbiterSettings {
  /// Channel names.
  struct Channels {
    std::string book_corner_stereo, servo_status, servo_request, markers, arm_state, detector_switch, grasp_point;
  } channels;
  std::string follow_logical_channel;   ///< DETECTOR_SWITCH.logical_channel this node answers to
  std::string follow_implementation;    ///< initial implementation of BOOK_CORNER_STEREO to follow
  CombinationTolerances tolerances;     ///< the paper's tolerances
  /// Not in the paper: without a valid P1, the front depth from BwS's regions just left of PS (stereo_front.*);
  /// off = no stereo depth (the invalid P1's depth or the model's plane, as before).
  bool use_stereo_front = true;
  StereoFrontProbe stereo_front;        ///< which region is the target's front
  BookSizeLimits size_limits;           ///< L_max of the gripper
  std::string cart_marker_role;         ///< MARKERS role of the cart marker
  /// Cart (grasp-frame) origin from the marker centre, in grasp axes (X up, Y right, Z into the shelf), m.
  Eigen::Vector3d grasp_origin_in_marker = Eigen::Vector3d::Zero();
  double book_front_z = 0;              ///< book-front plane Z in the grasp frame (GP.z without a valid P1)
  bool align_with_book_slope = true;    ///< rotate GP's orientation about Z by the servo's slope
  double max_slope_rad = 0.2;           ///< larger servo slopes are not trusted (GP keeps the grasp orientation)
  double width_settle_s = 0.2;          ///< the plate distance must hold this long (message time) ...
  double width_settle_tolerance = 0.0005;  ///< ... within this, with contact, to count as the book width
  double width_open_margin = 0.002;     ///< plates within this of L_max are open (touching a neighbour), not on a book
  /// Not in the paper: plates that open more than this beyond the measured BW while the TCP is still within
  /// width_abandon_within of where BW was read gave the grasp up (the coordinator backs out: more than the book
  /// between the plates); PS goes back to what it was before BW moved it.
  double width_abandon_open = 0.005;
  double width_abandon_within = 0.05;   ///< see width_abandon_open (m of TCP travel)
  double p1_arm_still_s = 0.5;          ///< a P1 counts only from a frame taken this long after the arm last moved
                                        ///< (0 = every frame)
  double p1_arm_still_joint_speed = 0.01;  ///< rad/s: a joint faster than this means the arm moves

  /// Reads and validates every key; throws ConfigError naming a bad one.
  static ArbiterSettings from_config(const Config& root);
};

/// The arbiter component.
class ArbiterNode : public Component {
 public:
  /// Reads its settings from `root` (see ArbiterSettings::from_config).
  explicit ArbiterNode(const Config& root);
  /// Same with settings already read (tests).
  ArbiterNode(const std::string& service, const std::string& implementation, ArbiterSettings settings);

  /// The implementation of BOOK_CORNER_STEREO followed now.
  const std::string& followed_implementation() const { return follow_; }

  /// Followed BOOK_CORNER_STEREO messages not used because their frame was taken while the
  /// arm moved or within p1.arm_still_s after.
  int64_t p1_skipped_arm_moving() const { return p1_skipped_arm_moving_; }

 private:
  void on_book_corner(const book_corner_stereo_t& msg);
  void on_servo_status(const servo_status_t& msg);
  void on_servo_request(const servo_request_t& msg);
  void on_markers(const marker_detections_t& msg);
  void on_arm_state(const arm_state_t& msg);
  void on_switch(const detector_switch_t& msg);

  void open_attempt();
  void publish_p1_check(int64_t utime, int64_t request_id);
  void decide(const servo_status_t& msg);
  grasp_point_t base_message(int64_t utime, int64_t request_id) const;
  Eigen::Vector3d to_grasp(const Eigen::Vector3d& p_base) const;
  Eigen::Vector3d to_base(const Eigen::Vector3d& p_grasp) const;
  /// Fills the inputs every decision shares: P1 (frozen or latest), PS and what is known about it, the fronts.
  CombinationInputs common_inputs() const;
  /// The attempt's stereo front depth left of `ps_grasp` (stereo_front_depth.h), if enabled and found.
  std::optional<double> stereo_front_z(const Eigen::Vector3d& ps_grasp) const;

  ArbiterSettings s_;
  std::string follow_;
  std::string switch_note_;                    ///< last switch, for GRASP_POINT.reason
  std::optional<Eigen::Isometry3d> frame_;     ///< grasp frame in base (from the cart marker)
  std::optional<Eigen::Vector3d> latest_p1_;   ///< base; empty when BwS found nothing
  bool have_p1_msg_ = false;                   ///< a followed BOOK_CORNER_STEREO arrived
  std::optional<Eigen::Vector3d> frozen_p1_;   ///< P1 of the attempt (base)
  std::vector<plane_region_t> latest_regions_;  ///< the followed BwS frame's regions (base)
  std::vector<plane_region_t> frozen_regions_;  ///< ... of the attempt
  bool frozen_ = false;
  /// The last P1 check: the P1 and PS (base) it judged and P1.y - PS.y (grasp frame) it measured.
  struct P1Check {
    Eigen::Vector3d p1_base;
    Eigen::Vector3d ps_base;
    double dy = 0.0;
  };
  std::optional<P1Check> last_check_;
  /// last_check_'s dy when the attempt's first BOOK_CORNER request came with that check's P1 frozen: the attempt's
  /// decisions judge P1 on it (CombinationInputs::p1_ps_dy_at_bwh_start).
  std::optional<double> attempt_check_dy_;
  std::optional<Eigen::Vector3d> ps_;          ///< base
  bool ps_measured_ = false;                   ///< ps_ is the stripe servo's end, not GP.y - BW
  /// The PS (base) at which a valid P1 led BwH to a left neighbour's corner (GraspOutcome::kP1LedAstray): at the
  /// same PS (within 3 mm: the stripe end measured again), P1 is not used again.
  std::optional<Eigen::Vector3d> p1_astray_at_ps_;
  /// The PS (base) at which BwH from PS found a shorter left neighbour's corner (GraspOutcome::kRaiseBwhStart): at
  /// the same PS (within 3 mm), BwH starts higher.
  std::optional<Eigen::Vector3d> raised_at_ps_;
  /// The shorter neighbour's corner (P2, base) that BwH from raised_at_ps_ found: the raised start lies above it.
  std::optional<Eigen::Vector3d> raised_over_corner_;
  /// The PS (base) at which BwH from PS found a corner left of and below a P1 on PS's left (GraspOutcome::
  /// kStartFromP1): at the same PS (within 3 mm), such a P1 is used.
  std::optional<Eigen::Vector3d> p1_between_at_ps_;
  /// The PS (base) at which BwH started from a P1 right of it and did not converge: at the same PS (within 3 mm),
  /// BwH starts from PS (CombinationInputs::p1_right_start_failed).
  std::optional<Eigen::Vector3d> p1_right_failed_at_ps_;
  /// R's depth (grasp Z) the corner servo triangulated for the last GRASP, and the PS (base) it was decided at:
  /// CombinationInputs::earlier_corner_z while PS stays that one (a failed attempt at the same book).
  struct CornerAtPs {
    Eigen::Vector3d ps;
    double z = 0.0;
  };
  std::optional<CornerAtPs> corner_at_ps_;
  std::map<int64_t, int> rank_of_request_;     ///< BOOK_CORNER request id -> rank
  int64_t last_decided_request_ = -1;
  // After a GRASP: book-width measurement.
  bool width_pending_ = false;
  int64_t width_request_ = 0;
  Eigen::Vector3d last_gp_grasp_ = Eigen::Vector3d::Zero();
  Eigen::Vector3d last_ps_grasp_ = Eigen::Vector3d::Zero();
  Eigen::Isometry3d last_frame_ = Eigen::Isometry3d::Identity();
  int64_t settle_start_utime_ = -1;
  double settle_start_width_ = 0;
  /// The last BOOK_WIDTH while the grasp may still be given up: BW, the TCP where it was read, PS before it moved.
  struct WidthTaken {
    int64_t request_id = 0;
    double bw = 0;
    Eigen::Vector3d tcp = Eigen::Vector3d::Zero();
    std::optional<Eigen::Vector3d> ps_before;
    bool ps_before_measured = false;
  };
  std::optional<WidthTaken> width_taken_;
  std::optional<int64_t> last_arm_motion_utime_;  ///< latest ARM_STATE that showed the arm moving
  int64_t p1_skipped_arm_moving_ = 0;
};

}  // namespace bookgrasp
