#include "services/eval_hand/hand_scene_eval.h"

#include <chrono>
#include <cmath>
#include <exception>
#include <random>
#include <stdexcept>
#include <vector>

#include "bookgrasp/marker_detections_t.hpp"
#include "bookgrasp/servo_request_t.hpp"
#include "bookgrasp/servo_status_t.hpp"
#include "bookgrasp/stereo_frame_t.hpp"
#include "common/config.h"
#include "common/image_conversion.h"
#include "common/pose_conversion.h"
#include "common/sim_render/sim_camera_rig.h"
#include "services/eval_hand/hand_servo_harness.h"
#include "services/marker_detector/marker_detector_node.h"

namespace bookgrasp {

namespace {

std::string state_name(int s) {
  switch (s) {
    case servo_status_t::CONVERGED:
      return "CONVERGED";
    case servo_status_t::FEATURE_LOST:
      return "FEATURE_LOST";
    case servo_status_t::TIMEOUT:
      return "TIMEOUT";
    case servo_status_t::FAILED:
      return "FAILED";
    case servo_status_t::RUNNING:
      return "RUNNING";
    case 0:
      return "NO_STATUS";
    default:
      return "STATE_" + std::to_string(s);
  }
}

void fill(const HandServoResult& r, HandTaskOutcome* t) {
  t->run = true;
  t->state = state_name(r.state);
  t->message = r.message;
  t->iterations = r.iterations;
  t->time_s = r.sim_time_s;
  t->converged = r.state == servo_status_t::CONVERGED && r.converged_pose.has_value();
}

void store(const Eigen::Vector3d& tcp, const Eigen::Vector3d& truth, HandTaskOutcome* t) {
  for (int k = 0; k < 3; ++k) {
    t->tcp_base[k] = tcp[k];
    t->truth_base[k] = truth[k];
  }
}

/// Marker detection times (ms) on the scene's stereo pair at its initial state: the frame is processed
/// `1 + repeats` times by one detector as a 10 Hz stream (utime 0.1 s apart, so the shipped tracking
/// searches the whole image once a second and regions in between) and the first (warm-up, whole) is dropped.
std::vector<double> time_markers(const HandSceneSettings& s, uint64_t seed, int repeats) {
  const Config root = Config::load_file(s.config_dir + "/marker_detector.yaml");
  MarkerDetectorSettings ms = MarkerDetectorSettings::from_config(root);
  ms.measure_processing_time = true;
  MarkerDetectorNode markers(ms);
  sim_render::SimCameraRig rig(s.scene_file, seed);
  const int64_t utime = 1'000'000;
  const sim_render::CameraImage left = rig.capture("stereo_left", utime);
  const sim_render::CameraImage right = rig.capture("stereo_right", utime);
  stereo_frame_t f{};
  f.utime = utime;
  f.left = mat_to_image(left.rgb, image_t::RGB8, utime, left.camera.frame);
  f.right = mat_to_image(right.rgb, image_t::RGB8, utime, right.camera.frame);
  f.left_calibration = left.camera.to_message(utime);
  f.right_calibration = right.camera.to_message(utime);
  f.baseline_m = (left.camera.camera_in_base.translation() - right.camera.camera_in_base.translation()).norm();
  std::vector<double> ms_per_frame;
  for (int k = 0; k <= repeats; ++k) {
    f.utime = f.left.utime = utime + k * 100'000;
    marker_detections_t md;
    std::string why;
    if (!markers.process(f, &md, &why)) throw std::runtime_error("marker detector refused the frame: " + why);
    if (k > 0) ms_per_frame.push_back(md.processing_ms);
  }
  return ms_per_frame;
}

}  // namespace

double slope_error_deg(const Eigen::Matrix3d& grasp_in_base, const Eigen::Matrix3d& gripper_in_base,
                       const Eigen::Matrix3d& book_in_base) {
  const Eigen::Vector3d g = grasp_in_base.transpose() * gripper_in_base.col(0);  // gripper x in the grasp frame
  const Eigen::Vector3d b = grasp_in_base.transpose() * book_in_base.col(2);     // book up in the grasp frame
  const double ag = std::atan2(g.y(), g.x()), ab = std::atan2(b.y(), b.x());
  return std::remainder(ag - ab, 2 * M_PI) * 180.0 / M_PI;
}

HandSceneOutcome evaluate_hand_scene(uint64_t seed, const HandSceneSettings& settings) {
  const auto wall0 = std::chrono::steady_clock::now();
  HandSceneOutcome o;
  o.seed = seed;
  try {
    const scene::Scene sc = scene::load_scene(settings.scene_file, seed);
    const ground_truth_t truth0 = scene_truth(sc);
    HandServoOptions opt;
    opt.config_dir = settings.config_dir;
    opt.camera_rate_hz = settings.camera_rate_hz;
    opt.debug_image_dir = settings.debug_image_dir;
    opt.debug_every_frames = settings.debug_every_frames;

    // Stripe servo from station A: PS against the true stripe end.
    {
      HandServoTask task;
      task.mode = servo_request_t::STRIPE_END;
      task.standoff_m = sc.shelf_depth_m - settings.station_a.z();
      task.timeout_s = settings.stripe_timeout_s;
      task.start_tcp = cart_grasp_pose(sc, settings.station_a);
      opt.debug_prefix = "seed" + std::to_string(seed) + "_stripe_";
      const HandServoResult r = run_hand_servo_task(sc, task, opt);
      if (!r.ik_ok) {
        o.stripe.state = "UNREACHABLE";
        o.stripe.message = "station A unreachable: " + r.ik_message;
      } else {
        fill(r, &o.stripe);
        o.bwh_ms.insert(o.bwh_ms.end(), r.bwh_ms.begin(), r.bwh_ms.end());
        o.bswh_ms.insert(o.bswh_ms.end(), r.bswh_ms.begin(), r.bswh_ms.end());
        if (o.stripe.converged) {
          const Eigen::Vector3d end(r.truth.stripe_end_base[0], r.truth.stripe_end_base[1], r.truth.stripe_end_base[2]);
          const Eigen::Vector3d e = grasp_pose_for_cart(sc, end).inverse() * r.converged_pose->translation();
          o.stripe.error_x_m = e.x();
          o.stripe.error_y_m = e.y();
          o.stripe.error_z_m = e.z() + task.standoff_m;
          store(r.converged_pose->translation(), end, &o.stripe);
        }
      }
    }

    // Corner servo from P1 + a seeded offset: P2 and the slope against the truth.
    {
      std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + 17);
      const double u1 = static_cast<double>(rng() >> 11) * 0x1.0p-53, u2 = static_cast<double>(rng() >> 11) * 0x1.0p-53;
      const double rad = settings.corner_max_offset_m * std::sqrt(u2), ang = 2 * M_PI * u1;
      o.corner_offset_x_m = rad * std::cos(ang);
      o.corner_offset_y_m = rad * std::sin(ang);
      HandServoTask task;
      task.mode = servo_request_t::BOOK_CORNER;
      task.standoff_m = settings.corner_standoff_m;
      task.timeout_s = settings.corner_timeout_s;
      const auto start = corner_start(sc, truth0, o.corner_offset_x_m, o.corner_offset_y_m, task.standoff_m);
      if (!start) {
        o.corner.state = "NO_TRUTH";
        o.corner.message = "the scene has no right-most book";
      } else {
        task.start_tcp = *start;
        opt.debug_prefix = "seed" + std::to_string(seed) + "_corner_";
        const HandServoResult r = run_hand_servo_task(sc, task, opt);
        if (!r.ik_ok) {
          o.corner.state = "UNREACHABLE";
          o.corner.message = "corner start unreachable: " + r.ik_message;
        } else {
          fill(r, &o.corner);
          o.bwh_ms.insert(o.bwh_ms.end(), r.bwh_ms.begin(), r.bwh_ms.end());
          o.bswh_ms.insert(o.bswh_ms.end(), r.bswh_ms.begin(), r.bswh_ms.end());
          const book_truth_t* b = nullptr;
          for (const book_truth_t& x : r.truth.books)
            if (x.rightmost) b = &x;
          if (o.corner.converged && b) {
            const Eigen::Vector3d p1(b->p1_base[0], b->p1_base[1], b->p1_base[2]);
            const Eigen::Isometry3d g = grasp_pose_for_cart(sc, p1);
            const Eigen::Vector3d e = g.inverse() * r.converged_pose->translation();
            o.corner.error_x_m = e.x();
            o.corner.error_y_m = e.y();
            o.corner.error_z_m = e.z() + task.standoff_m;
            store(r.converged_pose->translation(), p1, &o.corner);
            o.corner.slope_error_deg =
                slope_error_deg(g.linear(), r.converged_pose->linear(), pose_to_isometry(b->pose).linear());
          } else if (o.corner.converged) {
            o.corner.converged = false;
            o.corner.state = "NO_TRUTH";
            o.corner.message = "no right-most book in the truth at the end of the task";
          }
        }
      }
    }

    if (settings.run_markers) o.markers_ms = time_markers(settings, seed, 10);
  } catch (const std::exception& e) {
    o.error = e.what();
  }
  o.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return o;
}

}  // namespace bookgrasp
