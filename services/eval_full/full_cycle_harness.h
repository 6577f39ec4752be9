#pragma once
/// @file
/// The whole library cycle in one process (common/composition.h, memq://):
/// sim_world (drive: external), stereo_camera and hand_camera (sim backends),
/// marker_detector, bws_detector, bwh_detector, bswh_detector, visual_servo,
/// arbiter, planner, arm_driver and the coordinator, each built from its
/// config/services/<name>.yaml exactly as its process builds it. Only the keys
/// that tie them to one scene are overridden (scene file and seed, the
/// simulation's drive, camera frame rates if asked, the coordinator's progress
/// file and its demo "done" delay).
///
/// The harness steps physics in small steps of simulation time and spins the
/// bus after each, so every component sees message time only. It watches
/// TASK_STATUS, GRASP_POINT, SERVO_STATUS and SIM_GROUND_TRUTH and turns them into
/// what the evaluation measures (grasp attempts and their physical outcome, P1-P2
/// agreement, book width and stripe end against the truth, cycle time per book). Used by
/// tests/coordinator/full_cycle_test.cpp and the tool bookgrasp_eval_full.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "bookgrasp/ground_truth_t.hpp"
#include "bookgrasp/task_status_t.hpp"

namespace bookgrasp {

/// What to run and how.
struct FullCycleOptions {
  std::string source_dir;            ///< project source tree (config/services/*.yaml are read from it)
  std::string scene_file;            ///< scene YAML ("" = the one in sim_world.yaml); relative to source_dir
  uint64_t seed = 1;                 ///< scene seed (sim_world, both cameras)
  std::string progress_file;         ///< the coordinator's progress file (required; deleted at start if fresh)
  bool fresh_start = true;           ///< delete progress_file before building the coordinator
  double user_done_after_s = 1.0;    ///< coordinator user.auto_done_after_s (the demo's own "done")
  double stereo_rate_hz = 0;         ///< > 0 overrides stereo_camera sim.frame_rate_hz
  double hand_rate_hz = 0;           ///< > 0 overrides hand_camera sim.frame_rate_hz
  double physics_step_s = 0.01;      ///< simulation time per harness step (then the bus is spun)
  std::string log_file;              ///< "" = no log; else an LCM log of the bus (message time stamps)
  bool log_images = false;           ///< also log STEREO_IMAGES, HAND_IMAGE and BWS_DEBUG_IMAGE (large)
  std::vector<std::string> log_channels;  ///< not empty: log only these channels (e.g. a service's)
  std::string snapshot_dir;          ///< "" = none; else PNGs of the stereo/hand images at state changes
  double snapshot_period_s = 0;      ///< > 0: also a hand snapshot this often while a servo runs
  bool verbose = false;              ///< trace lines to stderr as they happen; also GRIP_DIAG (the target book
                                     ///< in the plates, truth) and HOLDER_DIAG (the book against the holder) lines
  /// Extra configuration overrides "service:dotted.key=value" (value parsed as YAML), applied
  /// after the harness's own; the key must exist in the service's YAML.
  std::vector<std::string> overrides;
};

/// One grasp decision of the arbiter (GRASP_POINT "GRASP ...").
struct GraspDecisionRecord {
  int book_index = 0;                ///< coordinator's current book
  bool p1_present = false;           ///< the decision had a P1 from BwS
  Eigen::Vector3d p1_grasp = Eigen::Vector3d::Zero();  ///< grasp frame, m
  Eigen::Vector3d p2_grasp = Eigen::Vector3d::Zero();
  Eigen::Vector3d gp_grasp = Eigen::Vector3d::Zero();
  Eigen::Vector3d p1_true_grasp = Eigen::Vector3d::Zero();  ///< true P1 of the right-most book, same frame
  /// GP_BASE (where the arm is sent, through the arbiter's cart frame) in the cart's true grasp frame: against
  /// p1_true_grasp it is the physical error, which gp_grasp (the arbiter's own frame) cannot show.
  Eigen::Vector3d gp_base_true_grasp = Eigen::Vector3d::Zero();
  bool truth_known = false;
  bool p1_valid = false;             ///< the arbiter used P1 (p1_used)
};

/// One converged stripe servo (BSwH, paper Section 2.3): PS, the TCP where the stripe end sat in the image centre,
/// against the simulation's true stripe end (SIM_GROUND_TRUTH.stripe_end_base at that moment), both in the cart's
/// true grasp frame. PS's Z is the servo's standoff, not a measurement, so only X and Y are compared (paper Fig. 14).
struct StripeRecord {
  int book_index = 0;                                        ///< coordinator's current book
  Eigen::Vector3d ps_true_grasp = Eigen::Vector3d::Zero();   ///< PS in the cart's true grasp frame, m
  Eigen::Vector3d end_true_grasp = Eigen::Vector3d::Zero();  ///< the true stripe end, same frame, m
};

/// A book on the upper shelf tilted further than this from upright does not stand (the scenes lean books by at most
/// 3 deg; a fallen book lies at 90, one leaning on the side panel at 15-50): the paper's grasp assumes standing books.
inline constexpr double kStandingMaxTiltDeg = 10.0;

/// One book taken (or tried) by the cycle.
struct BookRecord {
  int index = 0;                     ///< order in the cycle (0 = first)
  /// SIM_GROUND_TRUTH id of the book: right-most on the upper shelf at the start of the book, or the right-most
  /// standing one when that does not stand (passed_over_not_standing).
  int truth_id = -1;
  double true_width_m = 0;
  double measured_width_m = -1;      ///< arbiter BOOK_WIDTH (-1 = none)
  int grasp_attempts = 0;            ///< CLOSE_GRIPPER entries for this book (from the shelf)
  int grasp_successes = 0;           ///< ... after which the book, and no other, was in the gripper (physics)
  /// Ids of other books that came out of the upper shelf with the TCP in this book's grasps (a double lift:
  /// moved > 5 cm since the close, within 1 cm of where they sat in the TCP frame when EXTRACT ended).
  std::vector<int> carried_along;
  bool moved = false;                ///< completed the whole cycle (on the lower shelf)
  /// Too tall for, or not placeable on, the lower shelf: the coordinator left it on the holder (WAIT_BOOK_TAKEN)
  /// and sim_world's librarian took it out of the scene and said "taken".
  bool handed_over = false;
  /// Handed over because the lower shelf could not take it (the coordinator's retries.hand_over_unplaceable: its
  /// move there kept failing, or the shelf was full), not because it was too tall.
  bool handed_over_unplaceable = false;
  /// SIM_GROUND_TRUTH place of the book when the coordinator left RELEASE_ON_HOLDER ("" = it never did):
  /// "holder" = the book was put on the holder; anything else = lost on the way or while placing.
  std::string place_after_holder_release;
  /// When the coordinator left RETREAT_FROM_HOLDER (the gripper away): 1 = the book stands on the holder's
  /// ledge (truth: lowest corner within 2 cm of the ledge, its up within 35 deg of the back plate's), 0 = it
  /// does not (fell over, lies on the base, ...), -1 = not reached.
  int standing_on_holder = -1;
  /// Books right of this one on the upper shelf that leaned more than kStandingMaxTiltDeg (fallen over, or leaning on
  /// the side panel) at a TASK_STATUS change before this book's first close, in the order seen. While one did, the
  /// harness passed it over: truth_id became the right-most standing book (the paper's grasp takes standing books).
  std::vector<int> passed_over_not_standing;
  double start_s = 0;                ///< message time the book's attempt started (s from start)
  double end_s = -1;                 ///< message time it was counted moved
};

/// One close of the plates on the upper shelf: how much wider than the fore-edge the corner servo measured they
/// closed, and what became of it. The figures behind grasp.more_than_the_book_m.
struct PlateClose {
  double plates_m = 0;     ///< plate distance when the coordinator left CLOSE_GRIPPER (simulation)
  double fore_edge_m = 0;  ///< the last converged corner servo's front_width_m before the close (> 0)
  /// "held_alone" (the target and no other book out after EXTRACT), "double_lift" (the target with others),
  /// "not_held" (the target not in the plates after EXTRACT), "backed_out" (no EXTRACT: the coordinator's
  /// plate check, or nothing grasped).
  std::string outcome;
};

/// What happened in a run.
struct FullCycleResult {
  std::string end;                   ///< DONE, ABORTED, BUDGET, BOOKS (max_books reached), ERROR
  std::string message;               ///< coordinator's last message or the error
  int books_on_upper_shelf = 0;      ///< at the start (truth)
  int books_moved = 0;               ///< coordinator's count
  int grasp_attempts = 0;
  int grasp_successes = 0;
  int holder_releases = 0;  ///< RELEASE_ON_HOLDER left (the coordinator thinks the book is on the holder)
  int holder_placed = 0;    ///< ... with the book's truth place "holder"
  int holder_standing = 0;  ///< books standing on the holder's ledge after RETREAT_FROM_HOLDER (truth)
  std::vector<BookRecord> books;
  std::vector<GraspDecisionRecord> decisions;
  std::vector<PlateClose> closes;    ///< every close on the upper shelf with a measured fore-edge
  std::vector<StripeRecord> stripes;  ///< every converged stripe servo
  ground_truth_t final_truth;        ///< latest SIM_GROUND_TRUTH
  double sim_s = 0;                  ///< simulation time used
  double wall_s = 0;                 ///< wall time used (incl. building)
  std::vector<std::string> trace;    ///< TASK_STATUS state changes and arbiter decisions, with times
  std::vector<double> plan_ms;       ///< planner wall time per PLAN_RESULT (when reported)
};

/// The book with truth id `id` in `g`, or nullptr.
const book_truth_t* truth_book(const ground_truth_t& g, int id);

/// The composed system of one scene.
class FullCycleHarness {
 public:
  /// Builds every component from its configuration. Throws std::runtime_error
  /// or ConfigError (message says what) if one cannot be built.
  explicit FullCycleHarness(const FullCycleOptions& options);
  ~FullCycleHarness();
  FullCycleHarness(const FullCycleHarness&) = delete;
  FullCycleHarness& operator=(const FullCycleHarness&) = delete;

  /// Advances physics by one step and dispatches everything that fell due.
  void step();
  /// Steps until `stop()` is true (checked after every step), the coordinator
  /// is DONE or ABORTED, `max_books` books were moved (0 = no limit), or
  /// `budget_s` more seconds of simulation time passed. Returns the end word
  /// (DONE, ABORTED, BOOKS, BUDGET, STOP).
  std::string run_until(double budget_s, int max_books = 0, const std::function<bool()>& stop = nullptr);
  /// Destroys the coordinator component and builds a new one from the same
  /// configuration and progress file (a restarted process).
  void restart_coordinator();

  /// The latest TASK_STATUS (state "" before the first).
  const task_status_t& status() const;
  /// The latest SIM_GROUND_TRUTH.
  const ground_truth_t& truth() const;
  /// Simulation time since the start, s.
  double sim_time_s() const;
  /// What was measured so far.
  FullCycleResult result() const;
  /// The last left stereo and hand images (RGB; empty before the first).
  cv::Mat last_stereo_left() const;
  cv::Mat last_hand_image() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Runs one scene: builds the harness, runs until the coordinator is DONE or
/// ABORTED, `max_books` books were moved (0 = all) or `budget_s` of simulation
/// time. A setup error gives end = "ERROR" with the message; a configuration error (a bad file, key, value or
/// override, the same for every seed) throws ConfigError instead.
FullCycleResult run_full_cycle(const FullCycleOptions& options, double budget_s, int max_books = 0);

}  // namespace bookgrasp
