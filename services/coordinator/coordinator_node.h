#pragma once
/// @file
/// The coordinator process: runs the library cycle (library_cycle.h) on the
/// bus. Decodes ARM_STATE, MARKERS, GRASP_POINT, SERVO_STATUS, PLAN_RESULT and
/// USER_EVENT into events, sends the cycle's requests as SERVO_REQUEST,
/// PLAN_REQUEST, ARM_COMMAND, GRIPPER_COMMAND and USER_EVENT, reports
/// TASK_STATUS, and writes the progress file after every change.

#include <cstdint>
#include <map>
#include <string>

#include "bookgrasp/arm_state_t.hpp"
#include "bookgrasp/grasp_point_t.hpp"
#include "bookgrasp/joint_trajectory_t.hpp"
#include "bookgrasp/marker_detections_t.hpp"
#include "bookgrasp/plan_request_t.hpp"
#include "bookgrasp/plan_result_t.hpp"
#include "bookgrasp/servo_status_t.hpp"
#include "bookgrasp/user_event_t.hpp"
#include "common/component.h"
#include "common/config.h"
#include "services/coordinator/library_cycle.h"

namespace bookgrasp {

/// Parses the outcome word of a GRASP_POINT reason ("NEXT_REGION rank 2: ..." -> "NEXT_REGION", rank 2).
DecisionEvent decision_from_message(const grasp_point_t& msg);

/// The PLAN_REQUEST of a kPlan request `r` at `utime`: planner, tolerances and budget from `settings`, the goal,
/// the straight moves after it and the boxes to avoid (the books on the lower shelf), all in base.
plan_request_t plan_request_message(const CycleRequest& r, const CycleSettings& settings, int64_t utime);

/// The coordinator component.
class CoordinatorNode : public Component {
 public:
  /// Reads channels, roles, the progress file path and the cycle settings from `root`; resumes from the
  /// progress file when it exists. Throws ConfigError for a bad key or a corrupt progress file.
  explicit CoordinatorNode(const Config& root);

  /// The state machine (tests).
  const LibraryCycle& cycle() const { return cycle_; }

 private:
  void on_arm_state(const arm_state_t& msg);
  void on_markers(const marker_detections_t& msg);
  void on_grasp_point(const grasp_point_t& msg);
  void on_servo_status(const servo_status_t& msg);
  void on_plan_result(const plan_result_t& msg);
  void on_user_event(const user_event_t& msg);
  void send(const std::vector<CycleRequest>& requests, int64_t utime);
  void after_event(int64_t utime);

  struct Channels {
    std::string arm_state, markers, grasp_point, servo_status, plan_result, user_event;
    std::string servo_request, plan_request, arm_command, gripper_command, task_status;
  } ch_;
  std::string cart_role_, holder_role_;
  std::string progress_path_;
  double status_period_s_ = 1.0;
  CycleSettings settings_;
  LibraryCycle cycle_;
  std::map<int64_t, joint_trajectory_t> plans_;
  std::vector<std::string> joint_names_;
  int64_t last_status_utime_ = -1;
};

}  // namespace bookgrasp
