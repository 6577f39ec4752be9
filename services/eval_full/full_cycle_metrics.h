#pragma once
/// @file
/// The evaluation's figures over many scenes run by the full-cycle harness
/// (paper Section 5): grasp success, P1-P2 agreement, book width error, P1
/// error, stripe end error, cycle and planning time, failures by seed and reason.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "services/eval_full/full_cycle_harness.h"

namespace bookgrasp {

/// One scene's outcome as the evaluation keeps it.
struct SceneOutcome {
  uint64_t seed = 0;
  FullCycleResult result;
};

/// Tolerances the rates are measured with (paper Section 4.1 and 5).
struct MetricTolerances {
  double agreement_y_m = 0.015;  ///< P1-P2 agreement in Y (grasping tolerance)
  double agreement_x_m = 0.020;  ///< ... in X
  double width_m = 0.010;        ///< book width within this of the truth
  double stripe_x_m = 0.015;     ///< stripe end (PS) within this of the truth in X (paper Sec. 5, Fig. 14)
  double stripe_y_m = 0.010;     ///< ... and in Y
};

/// Summary statistics of a sample.
struct Stats {
  int n = 0;
  double mean = 0, median = 0, max = 0, min = 0, p95 = 0;
};
/// Statistics of `v` (all zero when empty).
Stats stats_of(std::vector<double> v);

/// The outcomes of a close (PlateClose::outcome), in the order of EvalMetrics::plates_over_fore_edge_mm.
inline constexpr const char* kCloseOutcomes[4] = {"held_alone", "double_lift", "not_held", "backed_out"};

/// Why a P1 and its P2 disagreed (kDisagreementModes[k], by P1 against the true corner in the P1-P2 tolerances): P1
/// more than agreement_y_m off in Y (another book's column), more than agreement_x_m above the corner (on a taller
/// neighbour's cover or front), more than agreement_x_m below it (the front's top missed), or P1 within both and P2
/// off.
inline constexpr const char* kDisagreementModes[4] = {"p1_off_in_y", "p1_above_corner", "p1_below_corner",
                                                      "p2_off_p1_near_corner"};

/// The index into kDisagreementModes of a decision whose P1 and P2 disagree; -1 when they agree, or P1 or the truth
/// is missing.
int disagreement_mode(const GraspDecisionRecord& d, const MetricTolerances& tol);

/// Everything metrics.json carries. A new field must also be listed in scene_record.cpp (counts() or samples()), or
/// resumed and merged runs lose it.
struct EvalMetrics {
  int scenes = 0;
  int books_targeted = 0;                    ///< books the cycle was asked to move (per scene: max_books or all)
  int books_moved = 0;
  int books_handed_over = 0;  ///< too tall for, or not placeable on, the lower shelf: left for the librarian
  int books_handed_over_unplaceable = 0;  ///< ... of them because the lower shelf could not take them
  /// Right-most books that did not stand (BookRecord::passed_over_not_standing): left on the upper shelf, the
  /// right-most standing book taken as the target instead. Scene records before stop 42 lack it (0).
  int books_passed_over_not_standing = 0;
  int grasp_attempts = 0;
  int grasp_successes = 0;      ///< grasps that held the target and no other book
  int books_carried_along = 0;  ///< other books a grasp took out of the shelf with the target
  /// Books no grasp targeted that were not on the upper shelf at the end of their scene (lifted along, pushed off,
  /// knocked down by the arm).
  int untargeted_books_off_the_upper_shelf = 0;
  int holder_releases = 0;                   ///< books the coordinator released on the holder
  int holder_placed = 0;                     ///< ... that were on it (truth) after the release
  int holder_retreats = 0;                   ///< ... from which the gripper retreated
  int holder_standing = 0;                   ///< ... and that then stood on the ledge (truth)
  /// Books the truth has on the lower shelf at the end (books_moved) in scenes that checked their pose, and of them
  /// the ones standing within kUprightMaxTiltDeg (truth_count.h) of upright (not knocked flat). Scene records before
  /// stop 31 lack both.
  int books_upright_checked = 0;
  int books_upright_on_lower_shelf = 0;
  int decisions = 0;                         ///< GRASP decisions with a P1
  int decisions_agreeing = 0;
  int widths = 0;                            ///< books with a measured width
  int widths_within = 0;
  std::vector<double> width_error_mm;        ///< |measured - true| per book
  std::vector<double> p1_error_mm[3];        ///< |P1 - true P1| per grasp-frame axis (X, Y, Z)
  std::vector<double> gp_error_mm[3];        ///< GP - true P1 (signed) per grasp-frame axis, every GRASP decision
  /// GP_BASE (where the arm is sent) - true P1 in the cart's true grasp frame: the physical error, which
  /// gp_error_mm (GP in the arbiter's own cart frame) does not show when the cart frame itself is off.
  std::vector<double> gp_base_error_mm[3];
  std::vector<double> p1_p2_dy_mm, p1_p2_dx_mm;  ///< P2 - P1 per decision
  int p1_p2_disagreements[4] = {0, 0, 0, 0};     ///< disagreeing decisions by kDisagreementModes
  int stripes = 0;                               ///< converged stripe servos (StripeRecord)
  int stripes_within = 0;  ///< ... with PS within MetricTolerances::stripe_x_m / stripe_y_m of the true end
  std::vector<double> stripe_error_mm[2];  ///< PS - true stripe end (signed) per grasp-frame axis X, Y
  /// Plates minus the corner servo's fore-edge at each close (PlateClose), by outcome: kCloseOutcomes[k].
  std::vector<double> plates_over_fore_edge_mm[4];
  std::vector<double> cycle_s;               ///< per moved book, message time
  std::vector<double> plan_ms;               ///< planner time per request
  std::vector<double> scene_wall_s;          ///< wall time per scene
  std::vector<std::pair<uint64_t, std::string>> failures;  ///< seed, reason
  std::map<std::string, int> failure_modes;  ///< reason class -> count
  /// The scenes (seeds, sorted, once each) that fell short in each kind of shortfall_counts: which to re-run alone.
  /// Scene records do not store it: a record is one scene, so its counts give its kinds (parse_scene_record).
  std::map<std::string, std::vector<uint64_t>> shortfall_seeds;
};

/// What fell short of the evaluation's aims (grasps that held the target alone, P1-P2 agreement, width within 1 cm)
/// and of the paper's stripe end tolerance in `m`, counted from its counts by kind: "grasp_not_held_alone",
/// "untargeted_book_off_the_upper_shelf", "p1_p2_" + each of kDisagreementModes, "p1_p2_unclassified" (disagreeing
/// without a P1 truth), "width_off_by_more_than_1cm", "stripe_end_outside_tolerance". Kinds with none are left out.
std::map<std::string, int> shortfall_counts(const EvalMetrics& m);

/// Where the simulation's truth has book `b` at the end of the scene ("unknown" if it has no such book).
std::string final_place(const FullCycleResult& r, const BookRecord& b);

/// The tilt of book `b`'s height axis from the vertical (base Z) at the end of the scene, degrees; NaN without truth.
double final_tilt_deg(const FullCycleResult& r, const BookRecord& b);

/// Ids of the books that no grasp of the cycle targeted and that the truth does not have on the upper shelf at the
/// end: taken along by a grasp of another book, pushed or knocked off.
std::vector<int> untargeted_books_off_the_upper_shelf(const FullCycleResult& r);

/// Books the coordinator moved (TASK_STATUS books_moved) that the truth has on the lower shelf at the end.
int books_on_lower_shelf(const FullCycleResult& r);

/// The failure class of a scene ("" = none): ERROR, DOUBLE_LIFT (a grasp took other books along), BOOK_NOT_ON_HOLDER (a
/// released book that the truth does not place on the holder: named before the abort it leads to),
/// BOOK_NOT_ON_LOWER_SHELF (a book the coordinator moved that the truth does not have on the lower shelf),
/// OTHER_BOOK_OFF_THE_UPPER_SHELF, ABORTED: <state>, BUDGET in <state>, GRASP_RETRIED, ..., and when nothing else
/// failed RIGHTMOST_NOT_STANDING (a right-most book passed over: BookRecord::passed_over_not_standing) or HANDED_OVER.
std::string failure_reason(const FullCycleResult& r, int max_books);

/// Accumulates `outcome` into `m` (max_books as given to the harness, 0 = all books).
void accumulate(const SceneOutcome& outcome, int max_books, const MetricTolerances& tol, EvalMetrics* m);

/// metrics.json text.
std::string metrics_json(const EvalMetrics& m, const std::string& command);

}  // namespace bookgrasp
