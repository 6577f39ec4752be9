#pragma once
/// @file
/// The planner component: PLAN_REQUEST (plan_request_t) -> PLAN_RESULT
/// (plan_result_t with a time-parameterised joint_trajectory_t). MARKERS
/// (marker_detections_t, roles "cart" / "holder", poses in base) move the cart
/// and holder boxes of the planning scene; until a marker is seen the nominal
/// poses of the configuration are used.

#include <map>
#include <memory>
#include <optional>
#include <string>

#include "bookgrasp/marker_detections_t.hpp"
#include "bookgrasp/plan_request_t.hpp"
#include "bookgrasp/plan_result_t.hpp"
#include "common/component.h"
#include "services/planner/planner_config.h"

namespace bookgrasp {

/// The planner service as a component.
class PlannerNode : public Component {
 public:
  /// Builds kinematics, scene and planner from `settings`; subscribes the request and marker channels.
  explicit PlannerNode(const PlannerSettings& settings);

  /// Answers one request (the core of the handler, usable without a bus). Bad requests get
  /// success = false, failure = INVALID_REQUEST / UNKNOWN_PLANNER and a message that says what is wrong.
  plan_result_t process(const plan_request_t& request) const;
  /// Applies one marker message to the scene. Returns false and a reason if a cart/holder pose is unusable.
  bool apply_markers(const marker_detections_t& markers, std::string* reason);
  /// The current environment boxes.
  const std::vector<SceneBox>& environment() const { return scene_.environment(); }
  /// The settings.
  const PlannerSettings& settings() const { return settings_; }

 private:
  void on_request(const plan_request_t& request);
  void on_markers(const marker_detections_t& markers);
  void answer(const plan_request_t& request);

  PlannerSettings settings_;
  std::unique_ptr<PlannerStack> stack_;
  PlanningScene scene_;  ///< environment only (no attached book)
  std::map<std::string, Eigen::Isometry3d> marker_poses_;
  std::optional<plan_request_t> deferred_;  ///< the newest request waiting for the first MARKERS
};

}  // namespace bookgrasp
