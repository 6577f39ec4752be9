#pragma once
/// @file
/// The hand-camera evaluation's figures (paper Section 5, Figures 13 and 14)
/// over seeded scenes: stripe end error (PS against the true stripe end), P2
/// error per axis (against the true P1), slope error, servo iterations and
/// time, detector time per frame; metrics.json, report.md and the PNG plots.
/// Pure: no simulation here (the outcomes come from hand_scene_eval).

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace bookgrasp {

/// One servo task's outcome, errors against the simulation's ground truth.
struct HandTaskOutcome {
  bool run = false;                  ///< the task was started (start pose reachable, truth available)
  bool converged = false;            ///< SERVO_STATUS CONVERGED
  std::string state;                 ///< final servo state name ("CONVERGED", "TIMEOUT", ..., "UNREACHABLE")
  std::string message;               ///< its message
  int iterations = 0;                ///< servo iterations (SERVO_STATUS.iterations)
  double time_s = 0;                 ///< request to final status, simulation time
  double error_x_m = 0;              ///< converged TCP - truth, grasp frame X (up)
  double error_y_m = 0;              ///< ... Y (right)
  double error_z_m = 0;              ///< ... Z (depth) minus the requested standoff (P2 only)
  double slope_error_deg = 0;        ///< gripper roll - book lean, about the approach axis (P2 only)
  double tcp_base[3] = {0, 0, 0};    ///< converged TCP position (PS or P2) in base
  double truth_base[3] = {0, 0, 0};  ///< the true point it is compared with (stripe end or P1) in base
};

/// One scene: the stripe servo from station A, the corner servo from an offset start, detector timings.
struct HandSceneOutcome {
  uint64_t seed = 0;
  HandTaskOutcome stripe;          ///< PBVS from station A: PS vs the true stripe end
  HandTaskOutcome corner;          ///< IBVS: P2 vs the true P1
  double corner_offset_x_m = 0;    ///< start offset of the corner task from P1 (grasp frame X)
  double corner_offset_y_m = 0;    ///< ... Y
  std::vector<double> bwh_ms;      ///< BwH processing time per frame (both tasks)
  std::vector<double> bswh_ms;     ///< BSwH processing time per frame
  std::vector<double> markers_ms;  ///< marker detection per frame (stereo left image, 640x480)
  double wall_s = 0;               ///< wall time of the scene
  std::string error;               ///< set up failed (exception text); the scene counts as failed
};

/// Tolerances of the rates (paper Sections 4.1, 5).
struct HandTolerances {
  double stripe_x_m = 0.015;  ///< stripe end: 1.5 cm in X (up)
  double stripe_y_m = 0.010;  ///< ... 1 cm in Y (right)
  double p2_x_m = 0.020;      ///< grasping tolerance P1-P2: 2 cm in X
  double p2_y_m = 0.015;      ///< ... 1.5 cm in Y
  double slope_deg = 3.0;     ///< slope within +-3 degrees
};

/// Statistics of a sample (all zero when empty).
struct HandStats {
  int n = 0;
  double mean = 0, median = 0, max = 0, min = 0, p95 = 0;
};
/// Statistics of `v`.
HandStats hand_stats(std::vector<double> v);

/// Everything metrics.json carries.
struct HandEvalMetrics {
  int scenes = 0;  ///< scenes run
  int stripe_runs = 0, stripe_converged = 0, stripe_within = 0;
  int corner_runs = 0, corner_converged = 0, corner_within = 0, slope_within = 0;
  std::vector<double> stripe_abs_mm[2];  ///< |PS - end| X, Y per converged stripe task
  std::vector<double> p2_abs_mm[3];      ///< |P2 - P1| X, Y, |Z - standoff| per converged corner task
  std::vector<double> slope_abs_deg;     ///< |slope error|
  std::vector<double> iterations, stripe_iterations, corner_iterations;
  std::vector<double> stripe_time_s, corner_time_s;
  std::vector<double> bwh_ms, bswh_ms, markers_ms;  ///< all frames of all scenes
  std::vector<double> scene_wall_s;
  struct Failure {
    uint64_t seed;
    std::string task, reason;
  };
  std::vector<Failure> failures;  ///< one per failed task (or scene set-up)
  int failed_scenes = 0;          ///< scenes with at least one failure
};

/// Accumulates one scene. A task fails when it did not converge or its error is outside `tol`.
void accumulate(const HandSceneOutcome& o, const HandTolerances& tol, HandEvalMetrics* m);

/// metrics.json text (`command`: the command line). With `scenes`, a per-scene list `runs` follows (state,
/// signed errors in mm, converged TCP and the true point in base, so the errors can be checked).
std::string hand_metrics_json(const HandEvalMetrics& m, const std::string& command,
                              const std::vector<HandSceneOutcome>& scenes = {});

/// The paper's Figure 14 for the stripe end: PS - true end as a scatter (Y right, X up, mm) with the tolerance box
/// (+-`tol_x_mm` X, +-`tol_y_mm` Y), beside the errors per run. `x_mm` and `y_mm` pair up by index. Also used by the
/// full-cycle evaluation (services/eval_full/eval_report.h).
cv::Mat stripe_end_figure(const std::vector<double>& x_mm, const std::vector<double>& y_mm, double tol_x_mm,
                          double tol_y_mm);

/// Writes `dir`/report.md, `dir`/figure13_p2_error.png (P2 - P1 per scene, X and Y with the grasping
/// tolerance; Z), `dir`/figure14_stripe_end.png (stripe end error scatter Y vs X with the tolerance box,
/// and per scene) and `dir`/slope_error.png. Throws std::runtime_error if a file cannot be written.
void write_hand_report(const std::string& dir, const HandEvalMetrics& m, const std::vector<HandSceneOutcome>& scenes,
                       const HandTolerances& tol, const std::string& command);

}  // namespace bookgrasp
