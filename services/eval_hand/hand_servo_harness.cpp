#include "services/eval_hand/hand_servo_harness.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bookgrasp/book_features_hand_t.hpp"
#include "bookgrasp/hand_image_t.hpp"
#include "bookgrasp/servo_request_t.hpp"
#include "bookgrasp/servo_status_t.hpp"
#include "bookgrasp/stripe_features_t.hpp"
#include "common/composition.h"
#include "common/config.h"
#include "common/grasp_frame.h"
#include "common/image_conversion.h"
#include "common/kinematics/arm_kinematics.h"
#include "common/kinematics/inverse_kinematics.h"
#include "common/pose_conversion.h"
#include "services/arm_driver/arm_driver_node.h"
#include "services/bswh_detector/bswh_detector_node.h"
#include "services/bwh_detector/bwh_detector_node.h"
#include "services/hand_camera/hand_camera_node.h"
#include "services/sim_world/sim_world.h"
#include "services/visual_servo/visual_servo_node.h"

namespace bookgrasp {

namespace {

/// Feeds ARM_SETPOINT / GRIPPER_SETPOINT from the bus into the SimWorld core.
class SimBridge : public Component {
 public:
  explicit SimBridge(SimWorld* world) : Component("sim_bridge", "harness"), world_(world) {
    subscribe("ARM_SETPOINT", &SimBridge::on_arm);
    subscribe("GRIPPER_SETPOINT", &SimBridge::on_gripper);
  }

 private:
  void on_arm(const arm_setpoint_t& m) { world_->apply_arm_setpoint(m); }
  void on_gripper(const gripper_setpoint_t& m) { world_->apply_gripper_setpoint(m); }
  SimWorld* world_;
};

/// Collects what the harness measures.
struct Sink {
  std::vector<servo_status_t> statuses;
  std::vector<double> bwh_ms, bswh_ms;
  hand_image_t last_image;
  bool have_image = false;
  int frames = 0;
  book_features_hand_t last_book;
  stripe_features_t last_stripe;
  void on_status(const lcm::ReceiveBuffer*, const std::string&, const servo_status_t* m) { statuses.push_back(*m); }
  void on_book(const lcm::ReceiveBuffer*, const std::string&, const book_features_hand_t* m) {
    bwh_ms.push_back(m->processing_ms);
    last_book = *m;
  }
  void on_stripe(const lcm::ReceiveBuffer*, const std::string&, const stripe_features_t* m) {
    bswh_ms.push_back(m->processing_ms);
    last_stripe = *m;
  }
  void on_image(const lcm::ReceiveBuffer*, const std::string&, const hand_image_t* m) {
    last_image = *m;
    have_image = true;
    ++frames;
  }
};

std::string cfg_path(const HandServoOptions& o, const std::string& name) {
  return (std::filesystem::path(o.config_dir) / (name + ".yaml")).string();
}

/// Projects a base-frame point with the hand image's calibration (no distortion in the sim).
bool project(const hand_image_t& img, const Eigen::Vector3d& p_base, cv::Point2d* px) {
  const Eigen::Vector3d pc = pose_to_isometry(img.calibration.camera_in_base).inverse() * p_base;
  if (pc.z() <= 1e-6) return false;
  *px = cv::Point2d(img.calibration.cx + img.calibration.fx * pc.x() / pc.z(),
                    img.calibration.cy + img.calibration.fy * pc.y() / pc.z());
  return true;
}

/// The image with the truth (P1 of each upper-shelf book: green = right-most, yellow = others;
/// stripe end: magenta) and the detections (R: red cross, stripe end: cyan cross). BGR.
cv::Mat overlay(const hand_image_t& img, const ground_truth_t& truth, const book_features_hand_t* book,
                const stripe_features_t* stripe) {
  cv::Mat rgb = image_to_mat(img.image), bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  cv::Point2d px;
  for (const book_truth_t& b : truth.books) {
    if (b.place != "upper_shelf") continue;
    if (project(img, Eigen::Vector3d(b.p1_base[0], b.p1_base[1], b.p1_base[2]), &px))
      cv::circle(bgr, px, b.rightmost ? 6 : 4, b.rightmost ? cv::Scalar(0, 255, 0) : cv::Scalar(0, 220, 255), 1,
                 cv::LINE_AA);
  }
  if (project(img, Eigen::Vector3d(truth.stripe_end_base[0], truth.stripe_end_base[1], truth.stripe_end_base[2]), &px))
    cv::circle(bgr, px, 6, cv::Scalar(255, 0, 255), 1, cv::LINE_AA);
  if (book && book->found && book->utime == img.utime)
    cv::drawMarker(bgr, cv::Point2d(book->r_px[0], book->r_px[1]), cv::Scalar(0, 0, 255), cv::MARKER_CROSS, 14, 1);
  if (stripe && stripe->end_found && stripe->utime == img.utime)
    cv::drawMarker(bgr, cv::Point2d(stripe->end_px[0], stripe->end_px[1]), cv::Scalar(255, 255, 0), cv::MARKER_CROSS,
                   14, 1);
  return bgr;
}

void save_debug(const HandServoOptions& o, const std::string& tag, const hand_image_t& img, const ground_truth_t& truth,
                const book_features_hand_t* book, const stripe_features_t* stripe) {
  if (o.debug_image_dir.empty()) return;
  std::filesystem::create_directories(o.debug_image_dir);
  cv::Mat raw;
  cv::cvtColor(image_to_mat(img.image), raw, cv::COLOR_RGB2BGR);
  cv::imwrite((std::filesystem::path(o.debug_image_dir) / (o.debug_prefix + tag + "_raw.png")).string(), raw);
  cv::imwrite((std::filesystem::path(o.debug_image_dir) / (o.debug_prefix + tag + ".png")).string(),
              overlay(img, truth, book, stripe));
}

}  // namespace

Eigen::Isometry3d grasp_pose_for_cart(const scene::Scene& scene, const Eigen::Vector3d& origin) {
  return grasp_frame_in_base(scene.cart_pose.linear().col(0), origin);
}

Eigen::Isometry3d cart_grasp_pose(const scene::Scene& scene, const Eigen::Vector3d& p_grasp) {
  // Grasp frame axes in cart axes: X = up (z), Y = right (-y), Z = into the shelf (x).
  const Eigen::Vector3d p_cart(p_grasp.z(), -p_grasp.y(), p_grasp.x());
  return grasp_pose_for_cart(scene, scene.cart_pose * p_cart);
}

Eigen::Vector3d cart_marker_in_grasp(const scene::Scene& scene, const ground_truth_t& truth) {
  const Eigen::Vector3d m = scene.cart_pose.inverse() * pose_to_isometry(truth.cart_marker).translation();
  return Eigen::Vector3d(m.z(), -m.y(), m.x());
}

std::optional<Eigen::Isometry3d> corner_start(const scene::Scene& scene, const ground_truth_t& truth, double dx,
                                              double dy, double standoff_m) {
  for (const book_truth_t& b : truth.books) {
    if (!b.rightmost) continue;
    const Eigen::Vector3d p1(b.p1_base[0], b.p1_base[1], b.p1_base[2]);
    const Eigen::Isometry3d g = grasp_pose_for_cart(scene, p1);
    return grasp_pose_for_cart(scene, g * Eigen::Vector3d(dx, dy, -standoff_m));
  }
  return std::nullopt;
}

ground_truth_t scene_truth(const scene::Scene& scene) {
  scene::SimModel model = scene::SimModel::build(scene);
  return model.ground_truth(0);
}

HandServoResult run_hand_servo_task(const scene::Scene& scene_in, const HandServoTask& task,
                                    const HandServoOptions& options) {
  const auto wall0 = std::chrono::steady_clock::now();
  HandServoResult result;

  // Arm at the start pose: IK from the scene's initial posture.
  const Config arm_cfg = Config::load_file(cfg_path(options, "arm_driver"));
  const ArmDriverCore probe = make_arm_driver_core(arm_cfg);
  IkParams ik_params;
  ik_params.max_restarts = 16;
  // A posture with the hand level and pointing forward, the elbow up (as the planner's preferred posture).
  ik_params.preferred_posture = Eigen::VectorXd::Zero(probe.kinematics().num_joints());
  ik_params.preferred_posture << 0.0, 0.3, 0.0, 1.6, 0.0, -0.33, 3.0;
  const InverseKinematics ik(probe.kinematics(), ik_params);
  const IkResult q = ik.solve(task.start_tcp, ik_params.preferred_posture);
  result.ik_ok = q.success;
  result.ik_message = q.reason;
  if (!q.success) return result;

  scene::Scene scene = scene_in;
  scene.initial_joints.assign(q.q.data(), q.q.data() + q.q.size());
  SimWorld world(scene, SimWorldTiming{});

  Composition comp;
  comp.add(std::make_unique<SimBridge>(&world));
  comp.add(std::make_unique<ArmDriverNode>(arm_cfg));

  HandCameraSettings cam = HandCameraSettings::from_config(Config::load_file(cfg_path(options, "hand_camera")));
  cam.backend = "sim";
  cam.image_encoding = "raw";
  cam.scene_file = scene.source;
  cam.seed = static_cast<int64_t>(scene.seed);
  cam.sim_frame_rate_hz = options.camera_rate_hz;
  comp.add(std::make_unique<HandCameraNode>(cam));
  comp.add(std::make_unique<BwhDetectorNode>(
      BwhDetectorSettings::from_config(Config::load_file(cfg_path(options, "bwh_detector")))));
  comp.add(std::make_unique<BswhDetectorNode>(
      BswhDetectorSettings::from_config(Config::load_file(cfg_path(options, "bswh_detector")))));
  VisualServoSettings vs = VisualServoSettings::from_config(Config::load_file(cfg_path(options, "visual_servo")));
  if (options.require_occlusion) vs.stripe.require_occlusion = *options.require_occlusion;
  if (options.search_direction) vs.stripe.search_direction = *options.search_direction == "left" ? -1 : 1;
  comp.add(std::make_unique<VisualServoNode>(vs));

  Sink sink;
  comp.bus().subscribe(vs.servo_status_channel, &Sink::on_status, &sink);
  comp.bus().subscribe(vs.book_features_channel, &Sink::on_book, &sink);
  comp.bus().subscribe(vs.stripe_features_channel, &Sink::on_stripe, &sink);
  comp.bus().subscribe(cam.output_channel, &Sink::on_image, &sink);

  const int64_t step = 10'000;  // SIM_STATE period (10 ms)
  int64_t t = world.now_utime();
  auto advance = [&](int64_t to) {
    const SimWorldOutputs out = world.advance_to(to);
    for (const sim_state_t& s : out.states) {
      comp.bus().publish(cam.sim_state_channel, &s);
      comp.spin();
    }
    for (const ground_truth_t& g : out.ground_truths) result.truth = g;
  };
  // A few states so the driver has measured the arm and published ARM_STATE.
  for (int i = 0; i < 5; ++i) advance(t += step);
  const size_t images_before = static_cast<size_t>(sink.frames);
  (void)images_before;

  servo_request_t req{};
  req.utime = t;
  req.request_id = 1;
  req.mode = static_cast<int8_t>(task.mode);
  req.start_pose = isometry_to_pose(task.start_tcp, "base", "gripper", t);
  req.fixed_depth_m = task.standoff_m;
  req.rank_from_right = task.rank_from_right;
  req.timeout_s = task.timeout_s;
  comp.bus().publish(vs.servo_request_channel, &req);
  comp.spin();
  const int64_t t_request = t;
  bool first_saved = false;
  int last_dumped = -1;
  const int64_t t_end = t + static_cast<int64_t>((task.timeout_s + 2.0) * 1e6);
  while (t < t_end) {
    advance(t += step);
    if (options.debug_every_frames > 0 && sink.have_image && sink.frames != last_dumped &&
        sink.frames % options.debug_every_frames == 0) {
      last_dumped = sink.frames;
      char tag[32];
      std::snprintf(tag, sizeof tag, "f%04d", sink.frames);
      save_debug(options, tag, sink.last_image, world.model().ground_truth(t), &sink.last_book, &sink.last_stripe);
    }
    if (!first_saved && sink.have_image) {
      save_debug(options, "first", sink.last_image, world.model().ground_truth(t), &sink.last_book, &sink.last_stripe);
      first_saved = true;
    }
    bool done = false;
    for (const servo_status_t& s : sink.statuses)
      if (s.request_id == req.request_id && s.state != servo_status_t::RUNNING && s.state != servo_status_t::IDLE) {
        result.state = s.state;
        result.message = s.message;
        result.iterations = s.iterations;
        result.sim_time_s = (s.utime - t_request) * 1e-6;
        if (s.state == servo_status_t::CONVERGED) result.converged_pose = pose_to_isometry(s.converged_pose);
        done = true;
      }
    if (done) break;
  }
  // Let the arm come to rest and the ground truth be published once more.
  advance(t += 100'000);
  result.truth = world.model().ground_truth(world.now_utime());
  if (sink.have_image) {
    save_debug(options, "last", sink.last_image, result.truth, &sink.last_book, &sink.last_stripe);
    result.last_image = image_to_mat(sink.last_image.image).clone();
    result.last_camera_in_base = pose_to_isometry(sink.last_image.calibration.camera_in_base);
  }
  result.last_book_found = sink.last_book.found;
  result.last_r_px = Eigen::Vector2d(sink.last_book.r_px[0], sink.last_book.r_px[1]);
  result.last_stripe_end_found = sink.last_stripe.end_found;
  result.last_stripe_end_px = Eigen::Vector2d(sink.last_stripe.end_px[0], sink.last_stripe.end_px[1]);
  result.bwh_ms = sink.bwh_ms;
  result.bswh_ms = sink.bswh_ms;
  result.frames = sink.frames;
  result.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return result;
}

}  // namespace bookgrasp
