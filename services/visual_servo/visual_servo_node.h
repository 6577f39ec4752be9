#pragma once
/// @file
/// The visual_servo component: SERVO_REQUEST starts/cancels a task;
/// BOOK_FEATURES_HAND (BwH) or STRIPE_FEATURES_HAND (BSwH) and ARM_STATE drive
/// it; ARM_COMMAND (CARTESIAN_VELOCITY in the gripper frame, then STOP) and
/// SERVO_STATUS (RUNNING, CONVERGED with P2/PS, FEATURE_LOST, TIMEOUT, ...) come
/// out. All timing in message time. The logic is ServoSession (servo_session.h).

#include <cstdint>
#include <memory>
#include <string>

#include "bookgrasp/arm_command_t.hpp"
#include "bookgrasp/arm_state_t.hpp"
#include "bookgrasp/book_features_hand_t.hpp"
#include "bookgrasp/servo_request_t.hpp"
#include "bookgrasp/servo_status_t.hpp"
#include "bookgrasp/stripe_features_t.hpp"
#include "common/component.h"
#include "common/config.h"
#include "services/visual_servo/servo_session.h"

namespace bookgrasp {

/// Everything the visual_servo node reads from its configuration.
struct VisualServoSettings {
  std::string servo_request_channel;   ///< channels.servo_request
  std::string book_features_channel;   ///< channels.book_features
  std::string stripe_features_channel; ///< channels.stripe_features
  std::string arm_state_channel;       ///< channels.arm_state
  std::string arm_command_channel;     ///< channels.arm_command
  std::string servo_status_channel;    ///< channels.servo_status
  std::string urdf_path;               ///< robot.urdf (absolute, resolved against the source tree)
  std::string tcp_link;                ///< robot.tcp_link
  std::string camera_link;             ///< robot.camera_link
  CameraIntrinsics camera;             ///< camera.*
  ServoSessionParams session;          ///< session.*
  BookCornerServoParams corner;        ///< book_corner.*
  StripeEndServoParams stripe;         ///< stripe_end.*

  /// Reads the configuration root. Throws ConfigError naming a bad key.
  static VisualServoSettings from_config(const Config& root);
};

/// The camera pose in the TCP frame from the URDF (both links fixed to the flange).
/// Throws std::runtime_error naming a missing link.
Eigen::Isometry3d camera_in_tcp_from_urdf(const std::string& urdf_path, const std::string& tcp_link,
                                          const std::string& camera_link);

/// The visual servo as a component.
class VisualServoNode : public Component {
 public:
  /// Loads the hand-eye geometry from the URDF; throws saying what is wrong.
  explicit VisualServoNode(const VisualServoSettings& settings);

  /// The session (for tests).
  const ServoSession& session() const { return session_; }

 private:
  void on_request(const servo_request_t& msg);
  void on_arm_state(const arm_state_t& msg);
  void on_book(const book_features_hand_t& msg);
  void on_stripe(const stripe_features_t& msg);
  void emit(const SessionOutput& out);

  VisualServoSettings settings_;
  ServoSession session_;
  int64_t command_id_ = 0;
};

}  // namespace bookgrasp
