#pragma once
/// @file
/// The paper's combination strategy (Section 3, Figure 8) and grasp tolerances
/// (Section 4.1), as a pure function of points in the `grasp` frame
/// (X up, Y right along the shelf as seen from the robot, Z into the shelf;
/// metres). No LCM in here: the arbiter node converts messages to these inputs.

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace bookgrasp {

/// Tolerances of the strategy, from configuration.
struct CombinationTolerances {
  double p1_ps_y = 0.01;   ///< |P1.y - PS.y| for P1 to be valid ("within few millimetres")
  double y = 0.015;        ///< grasping tolerance in Y (Section 4.1: 1.5 cm)
  double x = 0.02;         ///< grasping tolerance in X (half the plate height: 2 cm)
  int max_rank = 3;        ///< give up after BwH has tried this many regions from the right
  /// Not in the paper: a P2 both more than `y` left of a valid P1 and more than `x` above it is
  /// the corner of a taller left neighbour, not of the book P1 (checked against PS) belongs to;
  /// GP is then P1. False applies the paper's rules alone, which accept such a P2 in both axes.
  bool p1_over_other_book = true;
  /// Not in the paper: a P2 more than `y` right of PS (the paper: a false region, try the next) is accepted in Y
  /// when a P1 that failed the PS check lies within `y` of it: two sensors put the right-most book there, right of
  /// where the last grasp's PS says (a book the failed attempt dragged right, whose next region does not exist).
  bool p1_p2_agreement_over_ps = true;
  /// Not in the paper: a P1 that failed the check against PS still gives GP.z when it lies within this of the
  /// cart model's front plane (front_z_fallback): its book's fore-edge stands about as deep as the target's
  /// (flush, or pushed back with it by an earlier grasp's left plate), which the model's constant does not know.
  /// 0 = the paper (GP.z from the model whenever P1 is invalid).
  double invalid_p1_depth_range = 0.0;
  /// Not in the paper: use the corner R triangulated by the servo (CombinationInputs::hand_corner) for GP.z and
  /// P2.x when it lies within hand_corner_max_y_from_p2 of P2 in Y (it is the corner the servo centred) and within
  /// invalid_p1_depth_range of the model's front plane (0 there: no depth check).
  bool use_hand_corner = false;
  double hand_corner_max_y_from_p2 = 0.01;
  /// Not in the paper: with a valid P1 and a PS the stripe servo measured (CombinationInputs::ps_measured), a P2
  /// more than this left of PS is a left neighbour's corner that P1 led BwH to (a thin, short right-most book
  /// beside a taller one: P1 on the taller book passed the PS check). No grasp; the next attempt ignores P1 and
  /// starts BwH from PS (CombinationInputs::p1_led_astray). 0 = off (the paper accepts such a P2).
  double p2_ps_y = 0.0;
  /// Not in the paper: without a valid P1 and with a measured PS, a P2 more than `p2_ps_y` left of PS is a shorter
  /// left neighbour's corner: the right-most book is tall and its corner lies above the hand camera's view from PS
  /// at the stripe's height. No grasp (kRaiseBwhStart); the next check at this PS starts BwH this much higher (X).
  /// Once raised, such a P2 again gets no grasp (kNoGrasp: a failed attempt; the next one starts raised as well).
  /// 0 = off (the paper accepts such a P2). Needs p2_ps_y > 0.
  double raised_bwh_start_x = 0.0;
  /// Not in the paper: the raised start lies raised_bwh_start_x above the shorter neighbour's corner BwH found
  /// (CombinationInputs::neighbour_corner_x) when that is higher than PS, not above PS. The right-most book is
  /// taller than that neighbour; PS at the stripe's height says nothing about how much (far_cart seed 5273: the
  /// 290 mm book's corner 73 mm above PS + 100 mm, out of the hand camera's view; the 186 mm neighbour's taken
  /// again). False: above PS alone.
  bool raise_over_neighbour_corner = true;
  /// Not in the paper: without a valid P1, a P2 more than `y` left of and more than `x` below a P1 that failed the PS
  /// check on its left is a shorter left neighbour's corner: P1's book stands between it and PS. The right-most book
  /// is tall and leans left (its top corner fails the check against PS, which lies at the stripe's height) and its
  /// corner lies above the hand camera's view from PS. For any PS, measured or the estimate GP.y - BW (with a
  /// measured one the p2_ps_y rule answers first). No grasp (kStartFromP1); the next check at this PS takes that P1
  /// as valid (CombinationInputs::p1_between) and BwH starts from it. Such a P2 from there gets kNoGrasp.
  bool invalid_p1_over_p2 = false;
  /// Not in the paper: a P1 more than p1_ps_y right of a measured PS (CombinationInputs::ps_measured) stays invalid,
  /// but BwH starts from it, not from PS. The stripe end is the right-most book's right edge, so nothing BwS takes
  /// for a book front stands right of it unless the stripe servo took its end left of that edge: a shadow on the
  /// stripe above a short book between two tall ones (far_cart seeds 5117, 5282: PS 55-70 mm left of the right-most
  /// corner, BwH from PS took a book further left). P2 near P1 is then accepted by p1_p2_agreement_over_ps.
  /// Once BwH from such a P1 found no corner at this PS (CombinationInputs::p1_right_start_failed: far_cart seeds
  /// 5445, 5456: the right-most book leaning on the right side panel), BwH starts from PS again.
  /// False = the paper (BwH from PS).
  bool start_from_p1_right_of_measured_ps = false;
};

/// One decision of the strategy, with the numbers it was made on.
struct ValidationStep {
  std::string rule;        ///< e.g. "P1.y vs PS.y"
  double value = 0;        ///< the compared difference, metres
  double tolerance = 0;    ///< metres
  bool passed = false;     ///< the rule's condition held
  std::string decision;    ///< what was done and why
};

/// What the strategy concluded.
enum class GraspOutcome {
  kGrasp,       ///< GP is valid: grasp there
  kNextRegion,  ///< BwH chose a false region: run it again on the next region from the right
  kNoGrasp,     ///< no grasp point can be made (reason in the last step)
  /// P1 led BwH to a left neighbour's corner (CombinationTolerances::p2_ps_y): no grasp; the next attempt starts
  /// BwH from PS with P1 ignored.
  kP1LedAstray,
  /// Without a valid P1, BwH from PS found a corner left of the measured PS (CombinationTolerances::
  /// raised_bwh_start_x): no grasp; the next attempt starts BwH from PS raised in X.
  kRaiseBwhStart,
  /// Without a valid P1, BwH from PS found a corner left of and below a P1 that failed the PS check on its left
  /// (CombinationTolerances::invalid_p1_over_p2): no grasp; the next attempt starts BwH from that P1.
  kStartFromP1,
};

/// Inputs of one decision. P1 from BwS (may be missing), PS from BSwH or the
/// previous grasp, P2 from BwH servoing (may be missing when it failed).
struct CombinationInputs {
  std::optional<Eigen::Vector3d> p1;   ///< BwS corner, grasp frame
  Eigen::Vector3d ps;                  ///< stripe end / expected right edge of the next book
  std::optional<Eigen::Vector3d> p2;   ///< BwH end-effector position at convergence
  int p2_rank = 0;                     ///< which region from the right P2 came from (0 = right-most)
  /// Depth of the book fronts (Z) to use when P1 is invalid: the paper takes
  /// GP.z from P1; without P1 the node supplies the front plane from the cart
  /// model (marker + geometry). Required when p1 is missing or invalid.
  std::optional<double> front_z_fallback;
  /// Not in the paper: the depth of a stereo plane just left of PS (stereo_front_depth.h), the pushed target's
  /// front when P1 lies on another book. Used without a valid P1 when within invalid_p1_depth_range of
  /// front_z_fallback.
  std::optional<double> stereo_front_z;
  /// Not in the paper: R triangulated from the hand camera's views while the servo moved (grasp frame). Its Z is
  /// the target front's depth measured at the book (BwS's P1.z is 1.5 m away and misses pushed-back books), and
  /// its X is P2.x at that depth (the servo's converged pose assumed a depth).
  std::optional<Eigen::Vector3d> hand_corner;
  /// Not in the paper: R's depth (grasp Z) the corner servo triangulated in an earlier attempt at this same PS (the
  /// book not taken since). Without a valid P1 it gives the depth after the stereo front and before an invalid P1's
  /// or the model's, within invalid_p1_depth_range of the model: a book pushed deep by a failed insertion, which BwS
  /// no longer sees, is servoed at its own depth, not at the model's front plane.
  std::optional<double> earlier_corner_z;
  /// PS is the stripe end measured by the stripe servo (within a few mm of the book's right edge), not the
  /// estimate GP.y - BW after a grasp.
  bool ps_measured = false;
  /// At this PS, a valid P1 led BwH to a corner more than CombinationTolerances::p2_ps_y left of it before: P1 is
  /// not used (BwH starts from PS).
  bool p1_led_astray = false;
  /// At this PS, BwH from PS (no valid P1) found a corner more than CombinationTolerances::p2_ps_y left of it before:
  /// BwH starts CombinationTolerances::raised_bwh_start_x higher.
  bool bwh_start_raised = false;
  /// X (grasp frame) of the shorter left neighbour's corner (P2) that BwH from PS found at this PS before, with
  /// bwh_start_raised (CombinationTolerances::raise_over_neighbour_corner).
  std::optional<double> neighbour_corner_x;
  /// At this PS, BwH from PS found a corner left of and below a P1 that failed the PS check on its left before
  /// (CombinationTolerances::invalid_p1_over_p2): such a P1 is taken as valid, its book standing between.
  bool p1_between = false;
  /// At this PS, BwH started from a P1 right of it (CombinationTolerances::start_from_p1_right_of_measured_ps) and
  /// did not converge: BwH starts from PS.
  bool p1_right_start_failed = false;
  /// P1.y - PS.y as the P1 check that started this attempt's BwH measured it (the same P1 and PS). When set, P1 is
  /// judged on it instead of on p1 and ps: the node converts both from `base` with the grasp frame of the latest
  /// cart marker, which moves between the check and the decision, and a P1 at the tolerance's edge would otherwise
  /// change its verdict after BwH started from it (far_cart seed 5021: valid at 9.9 mm, invalid at the decision).
  std::optional<double> p1_ps_dy_at_bwh_start;
};

/// Result: GP (grasp frame) and every step.
struct CombinationResult {
  GraspOutcome outcome = GraspOutcome::kNoGrasp;
  Eigen::Vector3d gp = Eigen::Vector3d::Zero();  ///< GP = (P2.x, P2.y, P1.z) after validation
  bool p1_valid = false;                         ///< P1 passed the PS check and was used
  bool hand_corner_used = false;                 ///< CombinationInputs::hand_corner gave P2.x and GP.z
  int next_rank = 0;                             ///< for kNextRegion: the rank to ask BwH for
  /// Where BwH should start servoing: P1 if valid, else PS (Section 3.1) in X and Y. Its Z is the depth of the
  /// book's front the servo should assume: P1.z if valid, else front_depth_without_p1 (NaN when unknown).
  Eigen::Vector3d bwh_start = Eigen::Vector3d::Zero();
  /// Where bwh_start's Z came from when P1 is not valid (front_depth_without_p1's step); not in `steps`.
  ValidationStep front_depth_step;
  std::vector<ValidationStep> steps;
};

/// The target front's depth (Z) without a valid P1, and the step saying where it came from: the stereo plane
/// left of PS, else the invalid P1's own depth (each only within tol.invalid_p1_depth_range of the model's
/// plane), else the model's plane (front_z_fallback). Empty (with a failed step) when none is known.
std::optional<double> front_depth_without_p1(const CombinationInputs& in, const CombinationTolerances& tol,
                                             ValidationStep* step);

/// Step 1 only (Section 3.1): is P1 valid against PS, and where BwH starts. Not in the paper: without a valid P1
/// and with in.bwh_start_raised, the start is raised by tol.raised_bwh_start_x (step "BwH start raised"), above
/// in.neighbour_corner_x when that lies higher than PS and tol.raise_over_neighbour_corner.
/// Used before servoing; combine() repeats it so its trace is complete.
CombinationResult validate_p1(const CombinationInputs& in, const CombinationTolerances& tol);

/// The whole strategy: validate P1 against PS (3.1), then P2 against P1 (or PS
/// when P1 is invalid) in Y and X (3.2), then GP = (P2.x, P2.y, P1.z). With an accepted hand_corner
/// (tol.use_hand_corner), P2.x and GP.z come from it.
/// Inputs with NaN give kNoGrasp with a step naming the bad input.
CombinationResult combine(const CombinationInputs& in, const CombinationTolerances& tol);

/// Whether `r` started BwH from an invalid P1 right of a measured PS (step "P1 right of the measured PS",
/// CombinationTolerances::start_from_p1_right_of_measured_ps).
bool bwh_started_from_p1_right_of_ps(const CombinationResult& r);

/// The next PS after a successful grasp (Section 3): PS.y = GP.y - BW, where
/// BW is the book width measured by the gripper plates; x and z kept from PS.
Eigen::Vector3d next_ps(const Eigen::Vector3d& ps, const Eigen::Vector3d& gp, double book_width);

/// Book-size limits of Section 4.1, from the gripper's maximum opening L_max.
struct BookSizeLimits {
  double l_max = 0.06;        ///< maximum gripper opening
  double tcp_offset_y = 0.0;  ///< the gripper's middle right (+) of GP along Y (0 in the paper: on the right edge)
  /// Widest book the open plates straddle: how far left of the right edge the left plate lands
  /// (L_max/2 in the paper, where the gripper's middle is on the book's right edge).
  double s_max() const { return l_max / 2 - tcp_offset_y; }
  double s_min() const { return s_max() / 2; }  ///< narrowest book the alternation rule assumes
};

/// Whether a book of `width` (metres) is admissible (Section 4.1): wider than
/// S_max, the open left plate lands on the book itself; narrower than S_min
/// breaks the assumption that two neighbours together are at least S_max
/// wide (the left plate would reach the book after next). Returns the step
/// describing the check.
ValidationStep check_book_width(double width, const BookSizeLimits& limits);

/// Name of an outcome ("GRASP", "NEXT_REGION", "NO_GRASP").
std::string outcome_name(GraspOutcome o);

}  // namespace bookgrasp
