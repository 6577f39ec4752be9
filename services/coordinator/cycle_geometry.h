#pragma once
/// @file
/// Where the library cycle moves the gripper: the cart's grasp frame and the
/// holder's support frame from the markers, and every approach, grasp,
/// extraction and placement pose from configured geometry. Pure functions, no LCM.
///
/// Frames: `grasp` (cart) = origin at the upper shelf's front edge centre, X up,
/// Y right as seen from the robot, Z into the shelf; the same definition as the
/// arbiter's (config/services/arbiter.yaml `cart.grasp_origin_in_marker_m`).
/// Holder `support` frame = bottom front edge of the holder's back plate, x into
/// the back plate, y left along it, z up along it. Marker poses follow the
/// AprilTag convention of MARKERS (x right, y down, z into the tag).

#include <vector>

#include <Eigen/Geometry>

#include "common/config.h"

namespace bookgrasp {

/// Geometry of the cycle, all from configuration (metres).
struct CycleGeometry {
  // cart
  Eigen::Vector3d grasp_origin_in_marker = Eigen::Vector3d::Zero();  ///< grasp origin from the cart marker, grasp axes
  double shelf_left_y = -0.40;   ///< inner left end of the upper shelf, grasp Y
  double shelf_right_y = 0.40;   ///< inner right end, grasp Y
  // BSwH and BwH servo starts
  Eigen::Vector3d stripe_start = Eigen::Vector3d::Zero();  ///< position A (grasp frame)
  double stripe_fixed_depth = 0.2;  ///< distance kept to the rear board during the stripe servo
  /// The stripe servo is stopped when the TCP passes this grasp Y leftwards: further left the gripper comes nearer
  /// the book holder beside the cart than the planner's margin. The stripe is then free of books right of it.
  double stripe_left_limit_y = -0.40;
  double bwh_start_z = -0.15;       ///< fixed Z in front of the cart where BwH starts
  double bwh_start_offset_x = 0.0;  ///< added to the start point's X
  double book_front_z = 0.01;       ///< grasp Z of the books' fronts when the arbiter's P1 check gave no depth
  // grasp
  double grasp_offset_x = 0.0;      ///< TCP below (-) / above (+) GP along X
  double grasp_offset_y = 0.0;      ///< TCP right (+) of GP along Y
  double insertion_depth = 0.02;    ///< TCP this far beyond GP along Z
  /// > 0 (not in the paper): with the fore-edge's width measured by the corner servo, the plates open only this far
  /// beyond the book on its left (the right plate stays where grasp_offset_y and the full opening put it), so the
  /// open left plate lands on the neighbour next to the book, not on the one after it. 0 = always the full opening.
  double width_left_clearance = 0.0;
  /// Not in the paper: with the next fore-edge to the left measured by the corner servo, the open left plate's
  /// middle goes to that book's middle, so the plate pushes the neighbour back square instead of landing on a seam
  /// or on the book after it (which then stood between the plates: a double lift). Takes precedence over
  /// width_left_clearance; without a measured neighbour that rule (or the full opening) applies.
  bool left_plate_on_neighbour = false;
  double plate_thickness = 0.010;  ///< a plate's thickness across the books (Y)
  /// The left plate's inner face stays at least this far left of the book's measured fore-edge.
  double left_plate_min_clearance = 0.003;
  /// Not in the paper: plates closed this much wider than the fore-edge the corner servo measured hold more than the
  /// book (its neighbour too: a double lift). The attempt fails before the extraction, and the book's next attempts
  /// open the plates only to the fore-edge + retry_left_clearance. 0 = no check.
  double more_than_the_book = 0.0;
  double retry_left_clearance = 0.005;  ///< see more_than_the_book
  /// Not in the paper: the corner servo's fore-edge and the next one to its left closer than this are one page face
  /// that a dark page line split (join_split_fore_edge). 0 = never joined.
  double split_fore_edge_gap = 0.0;
  /// Not in the paper: the palm's half width across the books (Y). With it > 0, a right-most book near the right
  /// side panel (shelf_right_y) gets the plates and the palm moved left together, so that the palm stays
  /// right_panel_clearance left of the panel (plate_opening_clear_of_right_panel). 0 = no such shift.
  double palm_half_width = 0.0;
  double right_panel_clearance = 0.005;      ///< see palm_half_width
  double right_plate_min_clearance = 0.003;  ///< the right plate's inner face at least this far right of GP
  /// Not in the paper: the palm's front face this far behind the TCP along Z (lwa3_pg70.urdf: 30.9 mm). With it > 0,
  /// a book near the right side panel is first grasped less deep instead of with the plates and palm moved left: the
  /// TCP goes only so far beyond GP that the palm's face stays right_panel_clearance in front of the panels' front
  /// edge (side_panel_front_z), but at least min_insertion_depth (plate_grasp_clear_of_right_panel). 0 = the move left
  /// only.
  double palm_behind_tcp = 0.0;
  double min_insertion_depth = 0.005;  ///< see palm_behind_tcp (coordinator.yaml: 0.005)
  double side_panel_front_z = 0.0;    ///< grasp Z of the side panels' front edges
  double pre_grasp_distance = 0.10; ///< pre-grasp pose this far in front of GP along -Z
  /// Deepest GP (grasp Z) the pre-grasp and the extraction's end are measured from: a deeper front (books
  /// pushed back by an earlier grasp's left plate) gets the pre-grasp and the extraction's end a front at this
  /// depth would get: the plates in front of the planner's books box, the held book's box off the rear board.
  double deep_front_z = 0.035;
  double extract_lift = 0.01;       ///< first lift along the gripper x after the grasp
  /// The lift also moves the TCP this far towards the robot (along the gripper -z): a diagonal lift whose end
  /// brings the wrist nearer the shoulder (the stretched arm reaches the straight lift's end for no book at the
  /// shelf's right end; bookgrasp_cycle_reach). 0 = straight up.
  double extract_lift_out = 0.0;
  double extract_retreat = 0.40;    ///< then straight out along the gripper -z
  // holder
  Eigen::Vector3d holder_support_in_marker = Eigen::Vector3d::Zero();  ///< support origin, holder marker axes
  Eigen::Vector3d holder_place_tcp = Eigen::Vector3d::Zero();  ///< TCP in support; z gets the book height added
  Eigen::Matrix3d holder_gripper_axes = Eigen::Matrix3d::Identity();  ///< gripper axes in support (columns)
  Eigen::Vector3d holder_pre_place_offset = Eigen::Vector3d::Zero();  ///< pre-place = place + this (support)
  double holder_place_descent = 0.0;  ///< > 0: the place ends straight down the support's z from this far above
  /// The place on the holder counts as done when the arm stalls within this of the place pose: the book stands on
  /// the ledge, lower in the plates than its grasp put it (it slid down on the way; 0 = the pose must be reached).
  double holder_place_guard = 0.0;
  double lower_place_guard = 0.0;   ///< the same for the place on the lower shelf
  double holder_retreat = 0.10;     ///< after release, out along the gripper -z
  double holder_regrasp_lower = 0.0;  ///< the grasp from the holder puts the TCP this much lower on the book ...
  /// ... but not lower than this above the book's bottom (nor higher than the release): a short book's lower-shelf
  /// place needs the TCP that high (arm_2's reach down to the lower shelf). 0 = always holder_regrasp_lower.
  double holder_regrasp_min_height = 0.0;
  // lower shelf
  double lower_drop = 0.35;         ///< lower shelf surface below the upper one
  double lower_front_z = 0.01;      ///< fore-edges' plane on the lower shelf, grasp Z
  double lower_first_right_y = 0.38;///< right cover of the first book placed, grasp Y
  double lower_gap = 0.003;         ///< between books placed on the lower shelf
  /// At the release on the lower shelf the plates open this much wider than the book (0 = fully): a full opening
  /// swings the right plate into the book placed before.
  double lower_release_opening = 0.0;
  double lower_left_y = -0.40;      ///< inner left end of the lower shelf, grasp Y
  /// Not in the paper: a place on the lower shelf that stopped (a joint limit on its straight move) is tried again
  /// this much further left (grasp Y), where the arm reaches further down; 0 = the same slot again.
  double lower_retry_shift = 0.0;
  Eigen::Vector3d lower_pre_place_offset = Eigen::Vector3d::Zero();  ///< pre-place = place + this (grasp)
  double lower_retreat = 0.30;      ///< after release, out along -Z
  double lower_shelf_gap = 0.0;     ///< free height between the lower shelf and the upper one's underside (0 = unused)
  double held_top_above_tcp = 0.015;  ///< the planner's held-book box: its top above the TCP (planner.yaml)
  double lower_book_clearance = 0.0;  ///< a book goes to the lower shelf only with this much room above and below it
  double place_clearance = 0.005;   ///< book bottom this far above a support when released

  /// Reads the `geometry:` section; throws ConfigError naming a bad key.
  static CycleGeometry from_config(const Config& geometry);
};

/// The cart's grasp frame in base from the cart marker's pose in base.
Eigen::Isometry3d cart_grasp_frame(const Eigen::Isometry3d& cart_marker_in_base, const CycleGeometry& g);
/// The holder's support frame in base from the holder marker's pose in base.
Eigen::Isometry3d holder_support_frame(const Eigen::Isometry3d& holder_marker_in_base, const CycleGeometry& g);

/// A pose with the grasp frame's orientation at grasp-frame point `p`.
Eigen::Isometry3d pose_in_grasp_frame(const Eigen::Isometry3d& grasp_frame, const Eigen::Vector3d& p);
/// Gripper pose at the stripe servo's start A.
Eigen::Isometry3d stripe_start_pose(const Eigen::Isometry3d& grasp_frame, const CycleGeometry& g);
/// Gripper pose where BwH servoing starts, for the start point `start_grasp` (P1 or PS, grasp frame).
Eigen::Isometry3d bwh_start_pose(const Eigen::Isometry3d& grasp_frame, const Eigen::Vector3d& start_grasp,
                                 const CycleGeometry& g);
/// TCP pose that grasps the book: GP's gripper pose shifted by the offsets and the insertion depth.
Eigen::Isometry3d grasp_pose(const Eigen::Isometry3d& gp_base, const CycleGeometry& g);
/// GP's grasp Z as the moves around the grasp see it: min(gp_z, deep_front_z).
double moves_front_z(double gp_z, const CycleGeometry& g);

/// How far in front of GP (along -Z) the pre-grasp lies: pre_grasp_distance, plus how much deeper than
/// deep_front_z GP lies (`gp_z`: GP's grasp Z; not finite = no extra).
double pre_grasp_back_off(double gp_z, const CycleGeometry& g);

/// Pre-grasp pose: the grasp pose moved back along its z to `pre_grasp_distance` in front of GP, or in front
/// of grasp Z `deep_front_z` when GP lies deeper (`gp_z`: GP's grasp Z, into the shelf).
Eigen::Isometry3d pre_grasp_pose(const Eigen::Isometry3d& gp_base, double gp_z, const CycleGeometry& g);

/// How far the plates open for a grasp and where the TCP goes along Y.
struct PlateOpening {
  double width = 0.0;     ///< plate gap (m)
  double offset_y = 0.0;  ///< TCP right (+) of GP along Y (replaces CycleGeometry::grasp_offset_y)
};

/// What the corner servo measured across the fore-edges at R's depth (m; <= 0 or not finite: not measured).
struct ForeEdges {
  double front_width = 0.0;       ///< the target's fore-edge width
  double neighbour_offset = 0.0;  ///< how far left of R the next fore-edge's right edge lies
  double neighbour_width = 0.0;   ///< the next fore-edge's width
};

/// `reported` with a split page face joined. Two books' page faces are separated by both their covers (2 mm in the
/// simulated books, more on real hard covers); a dark line of the page texture can split one page face into two
/// fore-edges that touch. So when the next fore-edge's right edge lies less than g.split_fore_edge_gap left of the
/// target's left edge (neighbour_offset - front_width), the target's fore-edge reaches the next one's left edge
/// (front_width = neighbour_offset + neighbour_width) and the next fore-edge beyond is not known (neighbour 0).
/// Unchanged when either is not measured or split_fore_edge_gap is 0.
ForeEdges join_split_fore_edge(const ForeEdges& reported, const CycleGeometry& g);

/// The plates' opening for the fore-edges `edges` with the gripper's full opening `open_width`. The right plate's
/// inner face stays open_width / 2 + grasp_offset_y right of GP. The left one's inner face goes, with
/// left_plate_on_neighbour and the neighbour measured, to the neighbour's middle less half a plate (but at least
/// front_width + left_plate_min_clearance left of GP); else, with width_left_clearance > 0 and a measured width, to
/// front_width + width_left_clearance left of GP; never wider than the full opening. Otherwise: {open_width,
/// grasp_offset_y}.
PlateOpening plate_opening(const ForeEdges& edges, double open_width, const CycleGeometry& g);

/// The opening for a book whose earlier grasp closed on more than the book (more_than_the_book): the left plate's
/// inner face retry_left_clearance left of the measured fore-edge; the full opening when no width was measured.
PlateOpening plate_opening_after_more_than_the_book(const ForeEdges& edges, double open_width, const CycleGeometry& g);

/// `o` moved left, plates and palm together, so that for a GP at grasp Y `gp_y` the palm's right side stays
/// right_panel_clearance left of the right side panel (shelf_right_y). It moves no further than keeps the right
/// plate's inner face right_plate_min_clearance right of GP (the book's right edge); an opening narrowed to the book
/// (plate_opening) then opens further on the left, up to `open_width`, so that the palm can go as far left as with
/// the full opening; beyond that the palm may still meet the panel. `o` unchanged with palm_half_width 0, a GP far
/// enough from the panel, or a GP not finite.
PlateOpening plate_opening_clear_of_right_panel(const PlateOpening& o, double gp_y, double open_width,
                                                const CycleGeometry& g);

/// How far (m) the palm reaches past right_panel_clearance from the right side panel for a GP at grasp Y `gp_y`
/// with the opening `o` (> 0: it meets the panel or comes too near; <= 0: clear). 0 with palm_half_width 0.
double palm_over_right_panel(const PlateOpening& o, double gp_y, const CycleGeometry& g);

/// Where the plates go into the book: their opening across the books and how deep.
struct PlateGrasp {
  PlateOpening opening;          ///< plate gap and TCP offset along Y
  double insertion_depth = 0.0;  ///< TCP this far beyond GP along Z (replaces CycleGeometry::insertion_depth)
};

/// The grasp of the opening `o` at GP `gp` (grasp frame) clear of the right side panel. Where the palm would come
/// nearer the panel than right_panel_clearance (palm_over_right_panel), and palm_behind_tcp > 0: the plates go in
/// only so deep that the palm's face stays right_panel_clearance in front of the panels' front edge
/// (side_panel_front_z), when that is at least min_insertion_depth and the right plate itself (plate_thickness) stays
/// right_panel_clearance left of the panel. Otherwise the full insertion_depth with `o` moved left
/// (plate_opening_clear_of_right_panel). Far from the panel: `o` and insertion_depth.
PlateGrasp plate_grasp_clear_of_right_panel(const PlateOpening& o, const Eigen::Vector3d& gp, double open_width,
                                            const CycleGeometry& g);

/// The plate opening to release a book `book_width` wide on the lower shelf: the book plus
/// `lower_release_opening`, or 0 (the gripper's full opening) when that is 0.
double lower_release_width(double book_width, const CycleGeometry& g);

/// True when plates closed to `plate_distance` hold more than the fore-edge `edges.front_width` (a measured width
/// and more_than_the_book > 0 only).
bool holds_more_than_the_book(double plate_distance, const ForeEdges& edges, const CycleGeometry& g);
/// Book height above its support at the TCP: GP.x (top above the upper shelf) plus the X offset.
double tcp_height_on_book(const Eigen::Vector3d& gp_grasp, const CycleGeometry& g);
/// TCP height above the book's bottom for the grasp from the holder: `tcp_height` (the grasp from the shelf)
/// less `holder_regrasp_lower`, but at least `holder_regrasp_min_height` (and at most `tcp_height`); the holder
/// poses take it as their `tcp_height`.
double holder_regrasp_height(double tcp_height, const CycleGeometry& g);
/// TCP height above the book's bottom once it is in the plates after the grasp from the holder: the book
/// stood on the ledge, `place_clearance` below where it was released (what the lower-shelf poses take).
double height_held_from_holder(double tcp_height, const CycleGeometry& g);
/// TCP pose that puts the held book on the holder's ledge.
Eigen::Isometry3d holder_place_pose(const Eigen::Isometry3d& support, double tcp_height, const CycleGeometry& g);
/// Pre-place pose on the holder.
Eigen::Isometry3d holder_pre_place_pose(const Eigen::Isometry3d& support, double tcp_height, const CycleGeometry& g);
/// The straight moves from the pre-place pose that put the book on the holder: over the place pose at
/// `holder_place_descent` (if > 0), then down along the support's z to the place pose.
std::vector<Eigen::Isometry3d> holder_place_moves(const Eigen::Isometry3d& support, double tcp_height,
                                                  const CycleGeometry& g);
/// The straight moves that lift a book grasped on the holder back to the pre-place pose (the reverse).
std::vector<Eigen::Isometry3d> holder_lift_moves(const Eigen::Isometry3d& support, double tcp_height,
                                                 const CycleGeometry& g);
/// The tallest book the lower shelf takes: `lower_shelf_gap` - 2 `lower_book_clearance` (infinite without a gap).
double lower_shelf_max_book_height(const CycleGeometry& g);
/// The grasp Y of the next book's right cover on the lower shelf after a book `book_width` wide was placed with its
/// right cover at `right_y` (`lower_gap` between them).
double next_lower_right_y(double right_y, double book_width, const CycleGeometry& g);
/// A box: centre and axes in some frame, full edge lengths along the axes.
struct OrientedBox {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  ///< centre and axes
  Eigen::Vector3d size = Eigen::Vector3d::Zero();          ///< full edge lengths, m
};
/// The volume of a book standing on the lower shelf with its right cover at grasp Y `right_y`, `width` wide and
/// `height` tall, its fore-edge on the plane `lower_front_z` and `depth` deep into the shelf. Its axes are the grasp
/// frame's (x up: the height, y: the width, z into the cart: the depth); its pose is in base, the frame
/// `grasp_frame` is given in.
OrientedBox lower_shelf_book_box(const Eigen::Isometry3d& grasp_frame, double right_y, double width, double height,
                                 double depth, const CycleGeometry& g);
/// TCP pose that stands the held book on the lower shelf with its right cover at grasp Y `right_y`.
Eigen::Isometry3d lower_place_pose(const Eigen::Isometry3d& grasp_frame, double right_y, double book_width,
                                   double tcp_height, const CycleGeometry& g);
/// Pre-place pose on the lower shelf: the place pose moved by `lower_pre_place_offset`, raised (if that is
/// higher) so that the planner's held-book box of height `held_box_height` (its top `held_top_above_tcp` above the
/// TCP) sits in the middle of the gap between the shelves (`lower_shelf_gap` > 0).
Eigen::Isometry3d lower_pre_place_pose(const Eigen::Isometry3d& grasp_frame, double right_y, double book_width,
                                       double tcp_height, double held_box_height, const CycleGeometry& g);
/// The corner servo's standoff (distance from the TCP to the book's front along the approach) for a book front at
/// grasp Z `front_z`, the TCP held at `bwh_start_z`; at least 2 cm.
double servo_standoff(double front_z, const CycleGeometry& g);
/// The two straight moves of EXTRACT from the TCP pose `here`: up along the gripper's own x until the TCP is
/// `extract_lift` above `tcp_height` (its height on the book, grasp X) while out along its own -z until it is
/// `extract_lift_out` in front of `grasp_tcp_z` (the TCP's grasp Z at the grasp): one diagonal line; then out
/// along its own -z until it is `extract_retreat` in front of `grasp_tcp_z`. The targets are absolute in the
/// grasp frame `grasp_frame`, so an EXTRACT resumed or retried part-way ends where the first would have (a lift
/// relative to `here` took a resumed coordinator's arm 0.34 m beyond it, into a joint limit). Neither move goes
/// back: a TCP already higher or further out stays there.
std::vector<Eigen::Isometry3d> extract_moves(const Eigen::Isometry3d& here, const Eigen::Isometry3d& grasp_frame,
                                             double tcp_height, double grasp_tcp_z, const CycleGeometry& g);
/// `pose` moved by `d` along its own axes (x, y, z).
Eigen::Isometry3d move_along_own_axes(const Eigen::Isometry3d& pose, const Eigen::Vector3d& d);

}  // namespace bookgrasp
