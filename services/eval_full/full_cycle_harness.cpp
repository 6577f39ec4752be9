#include "services/eval_full/full_cycle_harness.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>

#include <mujoco/mujoco.h>
#include <yaml-cpp/yaml.h>
#include <lcm/lcm-cpp.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bookgrasp/book_features_hand_t.hpp"
#include "bookgrasp/grasp_point_t.hpp"
#include "bookgrasp/hand_image_t.hpp"
#include "bookgrasp/marker_detections_t.hpp"
#include "bookgrasp/plan_result_t.hpp"
#include "bookgrasp/servo_request_t.hpp"
#include "bookgrasp/servo_status_t.hpp"
#include "bookgrasp/stereo_frame_t.hpp"
#include "bookgrasp/stripe_features_t.hpp"
#include "common/composition.h"
#include "common/config.h"
#include "common/image_conversion.h"
#include "common/pose_conversion.h"
#include "common/scene/scene.h"
#include "common/service_host.h"
#include "services/eval_full/component_factories.h"
#include "services/sim_world/sim_world_node.h"
#include "services/task_watch/truth_count.h"

namespace bookgrasp {

namespace fs = std::filesystem;

namespace {

/// A service's YAML with some keys replaced; `source` keeps the file's path for messages.
struct ServiceYaml {
  std::string path;
  YAML::Node root;
  explicit ServiceYaml(const std::string& p) : path(p) {
    if (!fs::exists(p)) throw ConfigError("configuration file " + p + " does not exist");
    try {
      root = YAML::LoadFile(p);
    } catch (const YAML::Exception& e) {
      throw ConfigError(p + ": not valid YAML: " + e.what());
    }
  }
  /// Applies the "service:key=value" entries of `overrides` that name `service`.
  void apply(const std::string& service, const std::vector<std::string>& overrides) {
    for (const std::string& ov : overrides) {
      const auto colon = ov.find(':'), eq = ov.find('=');
      if (colon == std::string::npos || eq == std::string::npos || eq < colon)
        throw ConfigError("override '" + ov + "' is not service:dotted.key=value");
      if (ov.substr(0, colon) != service) continue;
      YAML::Node value;
      try {
        value = YAML::Load(ov.substr(eq + 1));
      } catch (const YAML::Exception& e) {
        throw ConfigError("override '" + ov + "': the value is not valid YAML: " + e.what());
      }
      set(ov.substr(colon + 1, eq - colon - 1), value);
    }
  }
  template <typename T>
  void set(const std::string& dotted, const T& value) {
    std::vector<std::string> parts;
    std::stringstream ss(dotted);
    for (std::string s; std::getline(ss, s, '.');) parts.push_back(s);
    std::vector<YAML::Node> chain{root};
    for (size_t i = 0; i + 1 < parts.size(); ++i) {
      YAML::Node next = chain.back()[parts[i]];
      if (!next.IsMap()) throw ConfigError(path + ": no section '" + parts[i] + "' for override " + dotted);
      chain.push_back(next);
    }
    if (!chain.back()[parts.back()].IsDefined()) throw ConfigError(path + ": override of unknown key " + dotted);
    chain.back()[parts.back()] = value;
  }
  std::string text() const {
    YAML::Emitter e;
    e << root;
    return e.c_str();
  }
  Config config() const { return Config::from_string(text(), path); }
};

double norm_finite(const double* v) {
  return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]) ? 1 : 0;
}

Eigen::Vector3d vec3(const double* v) {
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

std::string fmt(const char* f, double a) {
  char b[64];
  std::snprintf(b, sizeof b, f, a);
  return b;
}

/// The pose in the world of MuJoCo body `body` (after mj_forward / a step).
Eigen::Isometry3d body_pose(const mjData* d, int body) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) pose.linear()(r, c) = d->xmat[9 * body + 3 * r + c];
  pose.translation() = Eigen::Vector3d(d->xpos[3 * body], d->xpos[3 * body + 1], d->xpos[3 * body + 2]);
  return pose;
}

/// The position in the world of MuJoCo site `site`.
Eigen::Vector3d site_position(const mjData* d, int site) {
  return Eigen::Vector3d(d->site_xpos[3 * site], d->site_xpos[3 * site + 1], d->site_xpos[3 * site + 2]);
}

/// The pose in the world of MuJoCo site `site`.
Eigen::Isometry3d site_pose(const mjData* d, int site) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) pose.linear()(r, c) = d->site_xmat[9 * site + 3 * r + c];
  pose.translation() = site_position(d, site);
  return pose;
}

}  // namespace

const book_truth_t* truth_book(const ground_truth_t& g, int id) {
  for (const auto& b : g.books)
    if (b.id == id) return &b;
  return nullptr;
}

struct FullCycleHarness::Impl {
  FullCycleOptions o;
  std::chrono::steady_clock::time_point wall0 = std::chrono::steady_clock::now();
  scene::Scene scene;
  Composition comp;
  SimWorldNode* sim = nullptr;
  std::unique_ptr<Component> coordinator;
  std::string coordinator_yaml_path;
  std::string coordinator_yaml;
  std::unique_ptr<lcm::LogFile> log;
  int64_t log_events = 0;
  std::regex log_skip{"STEREO_IMAGES|HAND_IMAGE|BWS_DEBUG_IMAGE"};
  int64_t t0 = 0;
  int64_t t = 0;
  int64_t step_us = 10000;
  // channels
  std::string ch_status = "TASK_STATUS", ch_gp = "GRASP_POINT", ch_truth = "SIM_GROUND_TRUTH",
              ch_stereo = "STEREO_IMAGES", ch_hand = "HAND_IMAGE", ch_plan = "PLAN_RESULT", ch_markers = "MARKERS";
  std::string marker_roles = "-";
  std::string ch_servo = "SERVO_STATUS", ch_stripe = "STRIPE_FEATURES_HAND", ch_book = "BOOK_FEATURES_HAND";
  std::string last_gp_reason, last_servo_line, last_stripe_line, last_book_line;
  double last_front_width = 0;  ///< the last converged corner servo's fore-edge width (0 = none)
  int64_t last_servo_trace = 0;
  stripe_features_t last_stripe_f{};
  int64_t last_stripe_request = -1;  ///< the last STRIPE_END request recorded in res.stripes
  book_features_hand_t last_book_f{};
  // observations
  task_status_t status{};
  ground_truth_t truth{};
  stereo_frame_t last_stereo{};
  hand_image_t last_hand{};
  bool have_stereo = false, have_hand = false;
  FullCycleResult res;
  int snapshot_seq = 0;
  int target_book_id = -1;
  bool in_extract = false;
  /// Where the book sat in the TCP frame when the plates had closed (the coordinator left CLOSE_GRIPPER).
  std::optional<Eigen::Vector3d> book_in_tcp_at_close;
  /// Every other book on the upper shelf when the plates had closed: its centre in the TCP frame and in base.
  struct OtherBookAtClose {
    int id = -1;
    Eigen::Vector3d in_tcp, in_base;
  };
  std::vector<OtherBookAtClose> others_at_close;
  /// Books other than `target_id` (with `upper_shelf_only`, those the truth has on the upper shelf), where they sit
  /// now (TCP frame and base).
  std::vector<OtherBookAtClose> other_books_now(const ground_truth_t& truth, int target_id,
                                                bool upper_shelf_only) const {
    std::vector<OtherBookAtClose> out;
    const auto& model = sim->world().model();
    const int site = mj_name2id(model.model(), mjOBJ_SITE, "gripper");
    for (const auto& tb : truth.books) {
      if (tb.id == target_id || (upper_shelf_only && tb.place != "upper_shelf")) continue;
      const int body = mj_name2id(model.model(), mjOBJ_BODY, ("book_" + std::to_string(tb.id)).c_str());
      if (body < 0 || site < 0) continue;
      const Eigen::Vector3d c = body_pose(model.data(), body).translation();
      out.push_back({tb.id, site_pose(model.data(), site).inverse() * c, c});
    }
    return out;
  }
  /// Ids of the books in `others_at_close` that came out with the TCP: they moved more than 5 cm in base since the
  /// close and sit within 1 cm of where they sat in the TCP frame (lifted together with the target).
  std::vector<int> carried_along(const ground_truth_t& truth, int target_id) const {
    std::vector<int> ids;
    const auto now = other_books_now(truth, target_id, false);
    for (const auto& c : others_at_close)
      for (const auto& n : now)
        if (n.id == c.id && (n.in_base - c.in_base).norm() > 0.05 && (n.in_tcp - c.in_tcp).norm() < 0.01)
          ids.push_back(c.id);
    return ids;
  }
  /// The truth book `id`'s centre in the TCP frame (nullopt if there is no such book).
  std::optional<Eigen::Vector3d> book_in_tcp(int id) const {
    const auto& model = sim->world().model();
    const int body = mj_name2id(model.model(), mjOBJ_BODY, ("book_" + std::to_string(id)).c_str());
    const int site = mj_name2id(model.model(), mjOBJ_SITE, "gripper");
    if (body < 0 || site < 0) return std::nullopt;
    return site_pose(model.data(), site).inverse() * body_pose(model.data(), body).translation();
  }

  explicit Impl(const FullCycleOptions& opt) : o(opt) {
    if (o.source_dir.empty()) throw std::runtime_error("FullCycleOptions.source_dir is empty: give the source tree");
    if (o.progress_file.empty())
      throw std::runtime_error("FullCycleOptions.progress_file is empty: give a path for the coordinator's progress");
    if (!(o.physics_step_s > 0)) throw std::runtime_error("FullCycleOptions.physics_step_s must be > 0");
    step_us = static_cast<int64_t>(std::llround(o.physics_step_s * 1e6));
    const std::string cfg = o.source_dir + "/config/services/";

    // sim_world, in external drive.
    ServiceYaml sim_y(cfg + "sim_world.yaml");
    std::string scene_file = o.scene_file.empty() ? sim_y.root["scene"]["file"].as<std::string>() : o.scene_file;
    if (!fs::path(scene_file).is_absolute()) scene_file = o.source_dir + "/" + scene_file;
    if (!fs::exists(scene_file)) throw std::runtime_error("scene file " + scene_file + " does not exist");
    scene = scene::load_scene(scene_file, o.seed);
    sim_y.set("scene.file", scene_file);
    sim_y.set("scene.seed", static_cast<int64_t>(o.seed));
    sim_y.set("simulation.drive", std::string("external"));
    sim = &static_cast<SimWorldNode&>(add(sim_y, factories::sim_world));
    ch_truth = sim_y.root["channels"]["ground_truth"].as<std::string>();

    ServiceYaml stereo_y(cfg + "stereo_camera.yaml");
    stereo_y.set("backend", std::string("sim"));
    stereo_y.set("sim.scene_file", scene_file);
    stereo_y.set("sim.seed", static_cast<int64_t>(o.seed));
    if (o.stereo_rate_hz > 0) stereo_y.set("sim.frame_rate_hz", o.stereo_rate_hz);
    ch_stereo = stereo_y.root["channels"]["output"].as<std::string>();
    add(stereo_y, factories::stereo_camera);

    ServiceYaml hand_y(cfg + "hand_camera.yaml");
    hand_y.set("backend", std::string("sim"));
    hand_y.set("sim.scene_file", scene_file);
    hand_y.set("sim.seed", static_cast<int64_t>(o.seed));
    if (o.hand_rate_hz > 0) hand_y.set("sim.frame_rate_hz", o.hand_rate_hz);
    ch_hand = hand_y.root["channels"]["output"].as<std::string>();
    add(hand_y, factories::hand_camera);

    add(ServiceYaml(cfg + "marker_detector.yaml"), factories::marker_detector);
    add(ServiceYaml(cfg + "bws_detector.yaml"), factories::bws_detector);
    add(ServiceYaml(cfg + "bwh_detector.yaml"), factories::bwh_detector);
    add(ServiceYaml(cfg + "bswh_detector.yaml"), factories::bswh_detector);
    add(ServiceYaml(cfg + "visual_servo.yaml"), factories::visual_servo);
    add(ServiceYaml(cfg + "arbiter.yaml"), factories::arbiter);
    ServiceYaml plan_y(cfg + "planner.yaml");
    ch_plan = plan_y.root["channels"]["plan_result"].as<std::string>();
    add(plan_y, factories::planner);
    add(ServiceYaml(cfg + "arm_driver.yaml"), factories::arm_driver);

    // The coordinator lives outside the composition's list so it can be destroyed and rebuilt.
    ServiceYaml coord_y(cfg + "coordinator.yaml");
    coord_y.set("progress_file", o.progress_file);
    coord_y.set("user.auto_done_after_s", o.user_done_after_s);
    ch_status = coord_y.root["channels"]["task_status"].as<std::string>();
    ch_markers = coord_y.root["channels"]["markers"].as<std::string>();
    ch_servo = coord_y.root["channels"]["servo_status"].as<std::string>();
    ch_gp = coord_y.root["channels"]["grasp_point"].as<std::string>();
    coord_y.apply("coordinator", o.overrides);
    coordinator_yaml_path = coord_y.path;
    coordinator_yaml = coord_y.text();
    if (o.fresh_start) {
      std::error_code ec;
      fs::remove(o.progress_file, ec);
    }
    if (fs::path(o.progress_file).has_parent_path()) fs::create_directories(fs::path(o.progress_file).parent_path());
    build_coordinator();

    comp.bus().subscribe(ch_status, &Impl::on_status, this);
    comp.bus().subscribe(ch_gp, &Impl::on_gp, this);
    comp.bus().subscribe(ch_truth, &Impl::on_truth, this);
    comp.bus().subscribe(ch_stereo, &Impl::on_stereo, this);
    comp.bus().subscribe(ch_hand, &Impl::on_hand, this);
    comp.bus().subscribe(ch_plan, &Impl::on_plan, this);
    comp.bus().subscribe(ch_markers, &Impl::on_markers, this);
    comp.bus().subscribe(ch_servo, &Impl::on_servo, this);
    comp.bus().subscribe(ch_stripe, &Impl::on_stripe, this);
    comp.bus().subscribe(ch_book, &Impl::on_book, this);
    if (!o.log_file.empty()) {
      if (fs::path(o.log_file).has_parent_path()) fs::create_directories(fs::path(o.log_file).parent_path());
      log = std::make_unique<lcm::LogFile>(o.log_file, "w");
      if (!log->good()) throw std::runtime_error("cannot write the LCM log " + o.log_file);
      comp.bus().subscribe(".*", &Impl::on_any, this);
    }
    if (!o.snapshot_dir.empty()) fs::create_directories(o.snapshot_dir);

    // The first outputs (at the epoch) and the initial truth.
    t0 = sim->world().now_utime();
    t = t0;
    sim->advance_to(t);
    comp.spin();
    truth = sim->world().model().ground_truth(t);
    for (const auto& b : truth.books)
      if (b.place == "upper_shelf") ++res.books_on_upper_shelf;
  }

  Component& add(ServiceYaml y, const std::function<std::unique_ptr<Component>(const Config&)>& make) {
    y.apply(fs::path(y.path).stem().string(), o.overrides);
    const Config c = y.config();
    c.mark_read("service");
    std::unique_ptr<Component> component = make(c);
    c.require_all_read();
    const ServiceSettings settings = ServiceSettings::from_config(Config::from_string(y.text(), y.path));
    return comp.add_service(std::move(component), settings, y.text());
  }

  void build_coordinator() {
    const Config c = Config::from_string(coordinator_yaml, coordinator_yaml_path);
    c.mark_read("service");
    coordinator = factories::coordinator(c);
    c.require_all_read();
    coordinator->attach(&comp.bus(), [this] { return comp.now_utime(); });
  }

  void restart_coordinator() {
    comp.spin();
    coordinator->detach();
    coordinator.reset();
    trace("coordinator destroyed; rebuilt from " + o.progress_file);
    build_coordinator();
  }

  double rel_s(int64_t u) const { return static_cast<double>(u - t0) * 1e-6; }

  void trace(const std::string& line) {
    const std::string l = fmt("%9.2f ", rel_s(comp.now_utime() > 0 ? comp.now_utime() : t0)) + line;
    res.trace.push_back(l);
    if (o.verbose) std::cerr << l << "\n";
  }

  // ---- bus observers ----
  void on_any(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    if (!o.log_images && std::regex_match(channel, log_skip)) return;
    if (!o.log_channels.empty() &&
        std::find(o.log_channels.begin(), o.log_channels.end(), channel) == o.log_channels.end())
      return;
    lcm::LogEvent ev;
    ev.eventnum = log_events++;
    ev.timestamp = comp.now_utime();
    ev.channel = channel;
    ev.datalen = static_cast<int32_t>(rbuf->data_size);
    ev.data = rbuf->data;
    log->writeEvent(&ev);
  }

  void on_truth(const lcm::ReceiveBuffer*, const std::string&, const ground_truth_t* m) { truth = *m; }
  void on_stereo(const lcm::ReceiveBuffer*, const std::string&, const stereo_frame_t* m) {
    last_stereo = *m;
    have_stereo = true;
  }
  void on_hand(const lcm::ReceiveBuffer*, const std::string&, const hand_image_t* m) {
    last_hand = *m;
    have_hand = true;
  }
  void on_markers(const lcm::ReceiveBuffer*, const std::string&, const marker_detections_t* m) {
    std::string roles;
    for (const auto& k : m->markers)
      roles += (roles.empty() ? "" : ",") + (k.role.empty() ? std::to_string(k.id) : k.role);
    if (roles != marker_roles) {
      std::string poses;
      for (const auto& k : m->markers) {
        const auto& p = k.pose_in_base;
        char b[200];
        std::snprintf(b, sizeof b, " %s at (%.3f %.3f %.3f) q (%.3f %.3f %.3f %.3f);", k.role.c_str(), p.position[0],
                      p.position[1], p.position[2], p.orientation[0], p.orientation[1], p.orientation[2],
                      p.orientation[3]);
        poses += b;
        // Against the truth: position error in the cart's true grasp axes, rotation error.
        const ground_truth_t gt = sim->world().model().ground_truth(sim->world().now_utime());
        const pose_t* truth_pose = k.role == "cart"     ? &gt.cart_marker
                                   : k.role == "holder" ? &gt.holder_marker
                                                        : nullptr;
        if (truth_pose) {
          const Eigen::Isometry3d det = pose_to_isometry(p), tru = pose_to_isometry(*truth_pose);
          const Eigen::Vector3d e = (true_grasp(det.translation()) - true_grasp(tru.translation())) * 1e3;
          const double rot = Eigen::AngleAxisd(tru.linear().transpose() * det.linear()).angle() * 180 / M_PI;
          poses += fmt(" (truth: off (%.1f ", e.x()) + fmt("%.1f ", e.y()) + fmt("%.1f) mm in grasp axes, ", e.z()) +
                   fmt("turned %.2f deg);", rot);
        }
      }
      trace("MARKERS now: [" + roles + "]" + poses);
    }
    marker_roles = roles;
  }
  void on_servo(const lcm::ReceiveBuffer*, const std::string&, const servo_status_t* m) {
    const std::string line = "SERVO_STATUS " + std::to_string(m->request_id) + " mode " + std::to_string(m->mode) +
                             " state " + std::to_string(m->state) + ": " + m->message;
    const bool terminal = m->state != servo_status_t::RUNNING && m->state != servo_status_t::IDLE;
    if (terminal || (line != last_servo_line && m->utime - last_servo_trace >= 1000000)) {
      trace(line + fmt(" err_px %.1f", m->error_px[0]) + fmt(" %.1f", m->error_px[1]) + " it " +
            std::to_string(m->iterations));
      last_servo_trace = m->utime;
    }
    last_servo_line = line;
    if (m->mode == 1 && m->state == servo_status_t::CONVERGED) last_front_width = m->front_width_m;  // BOOK_CORNER
    if (m->mode == servo_request_t::STRIPE_END && m->state == servo_status_t::CONVERGED &&
        m->request_id != last_stripe_request && is_valid_pose(m->converged_pose)) {  // it repeats its final status
      last_stripe_request = m->request_id;
      const ground_truth_t gt = sim->world().model().ground_truth(sim->world().now_utime());
      StripeRecord s;
      s.book_index = status.current_book;
      s.ps_true_grasp = true_grasp(pose_to_isometry(m->converged_pose).translation());
      // The truth's stripe end is that of the right-most book; where that one does not stand (passed over, above),
      // the right-most standing book's edge is where the stripe should end.
      const book_truth_t* st = rightmost_standing(gt);
      s.end_true_grasp =
          true_grasp(st ? scene::stripe_end(scene, pose_to_isometry(st->pose), st->width_m, st->height_m, st->depth_m)
                        : vec3(gt.stripe_end_base));
      const Eigen::Vector3d e = (s.ps_true_grasp - s.end_true_grasp) * 1e3;
      trace(fmt("TRUTH PS - true stripe end (%.1f, ", e.x()) + fmt("%.1f) mm (X, Y)", e.y()));
      res.stripes.push_back(s);
    }
  }
  void on_stripe(const lcm::ReceiveBuffer*, const std::string&, const stripe_features_t* m) {
    last_stripe_f = *m;
    const std::string line = std::string("STRIPE_FEATURES found ") + (m->found ? "1" : "0") + " end " +
                             (m->end_found ? "1" : "0") + " " + m->failure_reason;
    if (line != last_stripe_line) trace(line + fmt(" end_px %.0f", m->end_px[0]) + fmt(" %.0f", m->end_px[1]));
    last_stripe_line = line;
  }
  void on_book(const lcm::ReceiveBuffer*, const std::string&, const book_features_hand_t* m) {
    last_book_f = *m;
    const std::string line = std::string("BOOK_FEATURES found ") + (m->found ? "1" : "0");
    if (line != last_book_line) trace(line + fmt(" R %.0f", m->r_px[0]) + fmt(" %.0f", m->r_px[1]));
    last_book_line = line;
  }
  void on_plan(const lcm::ReceiveBuffer*, const std::string&, const plan_result_t* m) {
    res.plan_ms.push_back(m->planning_time_s * 1e3);
    if (!m->success) trace("PLAN_RESULT " + std::to_string(m->request_id) + " failed: " + m->message);
  }

  BookRecord& book(int index) {
    while (static_cast<int>(res.books.size()) <= index) {
      BookRecord b;
      b.index = static_cast<int>(res.books.size());
      b.start_s = rel_s(comp.now_utime());
      res.books.push_back(b);
    }
    return res.books[index];
  }

  /// A book stands: its height axis within kStandingMaxTiltDeg of upright.
  static bool stands(const book_truth_t& k) { return height_axis_tilt_deg(k.pose) <= kStandingMaxTiltDeg; }
  /// Book `k`'s P1 lies right of book `o`'s (the true grasp frame's Y grows to the right).
  bool right_of(const book_truth_t& k, const book_truth_t& o) const {
    return true_grasp(vec3(k.p1_base)).y() > true_grasp(vec3(o.p1_base)).y();
  }
  /// The right-most book standing on the upper shelf, or nullptr.
  const book_truth_t* rightmost_standing(const ground_truth_t& g) const {
    const book_truth_t* standing = nullptr;
    for (const auto& k : g.books)
      if (k.place == "upper_shelf" && stands(k) && (!standing || right_of(k, *standing))) standing = &k;
    return standing;
  }

  /// True P1 of a book in the cart's true grasp frame (X up, Y right, Z into the shelf).
  Eigen::Vector3d true_grasp(const Eigen::Vector3d& p_base) const {
    const Eigen::Vector3d c = scene.cart_pose.inverse() * p_base;
    return Eigen::Vector3d(c.z(), -c.y(), c.x());
  }

  void on_status(const lcm::ReceiveBuffer*, const std::string&, const task_status_t* m) {
    const std::string prev = status.state;
    const int prev_moved = status.books_moved;
    status = *m;
    // sim_world's librarian took a book the coordinator left on the holder (too tall for the lower shelf, or the
    // lower shelf could not take it: "... could not take it (...)" in WAIT_BOOK_TAKEN): its "taken" ended the cycle.
    if (m->state == "WAIT_BOOK_TAKEN" && std::string(m->message).find("could not take it") != std::string::npos)
      book(m->books_moved).handed_over_unplaceable = true;
    if (prev == "WAIT_BOOK_TAKEN" && m->books_moved > prev_moved) book(prev_moved).handed_over = true;
    if (m->books_moved > prev_moved) {
      for (int i = prev_moved; i < m->books_moved; ++i) {
        BookRecord& b = book(i);
        b.moved = true;
        b.end_s = rel_s(m->utime);
      }
    }
    res.books_moved = m->books_moved;
    if (m->state == prev) return;
    trace("TASK_STATUS " + prev + " -> " + m->state + " (book " + std::to_string(m->current_book) + ", attempt " +
          std::to_string(m->attempt) + ", moved " + std::to_string(m->books_moved) + ") " + m->message);
    const ground_truth_t now_truth = sim->world().model().ground_truth(sim->world().now_utime());
    // The books on the lower shelf and how far each leans: as a book arrives (a move that swept into one shows
    // here), after each release and retreat, and at the end.
    if (o.verbose &&
        (m->state == "PLACE_ON_LOWER_SHELF" || (prev == "RETREAT_FROM_LOWER_SHELF" && m->state == "PARK") ||
         m->state == "DONE" || m->state == "ABORTED")) {
      std::string l = "TRUTH lower shelf (book id: tilt, base y):";
      for (const auto& tb : now_truth.books)
        if (tb.place == "lower_shelf")
          l += " " + std::to_string(tb.id) + fmt(": %.1f deg", height_axis_tilt_deg(tb.pose)) +
               fmt(" %.0f mm,", tb.pose.position[1] * 1e3);
      trace(l);
    }
    if (m->state == "WAIT_P1_CHECK" || m->state == "MOVE_TO_STRIPE_START" || m->state == "MOVE_TO_BWH_START") {
      BookRecord& b = book(m->current_book);
      if (b.truth_id < 0) {
        for (const auto& tb : now_truth.books)
          if (tb.rightmost && tb.place == "upper_shelf") {
            b.truth_id = tb.id;
            b.true_width_m = tb.width_m;
          }
      }
      target_book_id = b.truth_id;
    }
    if (prev == "RELEASE_ON_HOLDER") {
      // The coordinator believes the book is on the holder now; physics decides.
      BookRecord& b = book(m->current_book);
      const book_truth_t* tb = truth_book(now_truth, b.truth_id);
      b.place_after_holder_release = tb ? tb->place : std::string("unknown");
      ++res.holder_releases;
      if (b.place_after_holder_release == "holder") ++res.holder_placed;
      trace(std::string("HOLDER ") + (b.place_after_holder_release == "holder" ? "placed" : "NOT PLACED") +
            ": book id " + std::to_string(b.truth_id) + " is " + b.place_after_holder_release);
    }
    if (prev == "RETREAT_FROM_HOLDER") {
      BookRecord& b = book(m->current_book);
      const book_truth_t* tb = truth_book(now_truth, b.truth_id);
      double lowest = 1e9, up = -1;
      if (tb) {
        const Eigen::Isometry3d inv = scene.holder_support_pose.inverse();
        for (const auto& c : tb->corners_base) lowest = std::min(lowest, (inv * vec3(c)).z());
        const Eigen::Isometry3d pose = pose_to_isometry(tb->pose);
        up = pose.linear().col(2).dot(scene.holder_support_pose.linear().col(2));
      }
      const bool standing = tb && tb->place == "holder" && std::abs(lowest) <= 0.02 && up >= std::cos(35 * M_PI / 180);
      b.standing_on_holder = standing ? 1 : 0;
      if (standing) ++res.holder_standing;
      trace(std::string("HOLDER ") + (standing ? "standing" : "NOT STANDING") + ": book id " +
            std::to_string(b.truth_id) + fmt(" lowest corner %.3f m above the ledge,", lowest) +
            fmt(" up %.0f deg from the back plate's", std::acos(std::clamp(up, -1.0, 1.0)) * 180 / M_PI));
    }
    if (target_book_id >= 0 && m->current_book >= 0 && m->current_book < static_cast<int>(res.books.size())) {
      // Does the target still stand? Books fall by themselves in some scenes (a neighbour leaning onto the right-most
      // one, a thin book creeping over). Until the book's first close, a target that does not stand is passed over:
      // the target becomes the right-most standing book (the paper's grasp takes standing books; the arbiter's
      // "no corner from P1: BwH from PS" is there for a book leaning on the side panel).
      BookRecord& b = res.books[m->current_book];
      const book_truth_t* tb = truth_book(now_truth, b.truth_id);
      const bool seen = std::find(b.passed_over_not_standing.begin(), b.passed_over_not_standing.end(),
                                  b.truth_id) != b.passed_over_not_standing.end();  // and no book stood then
      if (tb && !seen && b.truth_id == target_book_id && b.grasp_attempts == 0 && tb->place == "upper_shelf" &&
          !stands(*tb)) {
        const book_truth_t* standing = rightmost_standing(now_truth);
        std::string passed;
        for (const auto& k : now_truth.books)
          if (k.place == "upper_shelf" && !stands(k) && (!standing || right_of(k, *standing)) &&
              std::find(b.passed_over_not_standing.begin(), b.passed_over_not_standing.end(), k.id) ==
                  b.passed_over_not_standing.end()) {
            b.passed_over_not_standing.push_back(k.id);
            passed += " " + std::to_string(k.id) + fmt(" (%.1f deg)", height_axis_tilt_deg(k.pose));
          }
        trace("TRUTH RIGHT-MOST NOT STANDING (entering " + m->state + "): book id(s)" + passed +
              " passed over; the target is now " +
              (standing ? "book id " + std::to_string(standing->id) + ", the right-most standing book"
                        : std::string("none (no book stands)")));
        if (standing) {
          b.truth_id = standing->id;
          b.true_width_m = standing->width_m;
        }
        target_book_id = b.truth_id;
      }
    }
    if (m->state == "CLOSE_GRIPPER") {
      BookRecord& b = book(m->current_book);
      ++b.grasp_attempts;
      ++res.grasp_attempts;
      in_extract = true;
    }
    if (prev == "CLOSE_GRIPPER" && last_front_width > 0) {
      res.closes.push_back(PlateClose{sim->world().model().gripper_width(), last_front_width,
                                      m->state == "EXTRACT" ? "" : "backed_out"});
    }
    if (in_extract && prev == "CLOSE_GRIPPER") {
      const int id = book(m->current_book).truth_id;
      book_in_tcp_at_close = book_in_tcp(id);
      others_at_close = other_books_now(now_truth, id, true);
    }
    if (in_extract && prev == "EXTRACT") {
      in_extract = false;
      BookRecord& b = book(m->current_book);
      const book_truth_t* tb = truth_book(now_truth, b.truth_id);
      // Held: both plates touch it (the truth's "gripper"), or it came out of the shelf with the TCP, sitting where
      // it sat when the plates closed (within 1 cm): MuJoCo's contacts flicker, and at stop 22 six of ten books the
      // "gripper" test failed at this instant were carried on to the holder.
      const auto now_in_tcp = book_in_tcp(b.truth_id);
      const bool carried = tb && tb->place == "other" && book_in_tcp_at_close && now_in_tcp &&
                           (*now_in_tcp - *book_in_tcp_at_close).norm() < 0.01;
      const bool held = tb && (tb->place == "gripper" || carried);
      // A grasp that brings other books out with the target is not a success: the task takes one book at a time.
      const std::vector<int> along = carried_along(now_truth, b.truth_id);
      b.carried_along.insert(b.carried_along.end(), along.begin(), along.end());
      std::string along_text;
      for (int id : along) along_text += (along_text.empty() ? "" : ", ") + std::to_string(id);
      if (!along.empty()) trace("GRASP TOOK MORE: book id(s) " + along_text + " came out with the TCP as well");
      if (held && along.empty()) {
        ++b.grasp_successes;
        ++res.grasp_successes;
      }
      if (!res.closes.empty() && res.closes.back().outcome.empty())
        res.closes.back().outcome = !held ? "not_held" : along.empty() ? "held_alone" : "double_lift";
      trace(std::string("GRASP ") + (held ? (along.empty() ? "held" : "held with other books: FAILED") : "FAILED") +
            ": book id " + std::to_string(b.truth_id) + " is " + (tb ? tb->place : std::string("unknown")) +
            (carried ? " (carried: it moved with the TCP since the close, one plate's contact off this instant)" : ""));
    } else if (in_extract && m->state != "EXTRACT" && m->state != "CLOSE_GRIPPER") {
      in_extract = false;  // the close itself failed (nothing grasped); counted as a failed attempt
      trace("GRASP FAILED at close: " + m->message);
    }
    if (o.verbose && target_book_id >= 0) grip_diag();
    snapshot(m->state);
  }

  /// Verbose: where the TCP is on the target book (book body frame: x depth, y width, z height).
  void grip_diag() {
    const auto& model = sim->world().model();
    const mjModel* mm = model.model();
    const mjData* dd = model.data();
    const int body = mj_name2id(mm, mjOBJ_BODY, ("book_" + std::to_string(target_book_id)).c_str());
    const int site = mj_name2id(mm, mjOBJ_SITE, "gripper");
    if (body < 0 || site < 0) return;
    const Eigen::Isometry3d pose = body_pose(dd, body);
    const Eigen::Vector3d tcp = site_position(dd, site);
    const Eigen::Vector3d in_book = pose.inverse() * tcp;
    const Eigen::Vector3d in_cart = scene.cart_pose.inverse() * tcp;
    double h = 0, d = 0;
    for (const auto& bk : scene.books)
      if (bk.id == target_book_id) h = bk.height_m, d = bk.depth_m;
    // The book's rotation in the gripper from the grasp's (book x = gripper z, y = -y, z = x), gripper axes, deg.
    Eigen::Matrix3d g;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) g(r, c) = dd->site_xmat[9 * site + 3 * r + c];
    Eigen::Matrix3d nominal;
    nominal.col(0) = Eigen::Vector3d::UnitZ();
    nominal.col(1) = -Eigen::Vector3d::UnitY();
    nominal.col(2) = Eigen::Vector3d::UnitX();
    const Eigen::AngleAxisd aa(g.transpose() * pose.linear() * nominal.transpose());
    const Eigen::Vector3d rv = aa.axis() * aa.angle() * 180 / M_PI;
    char l[400];
    std::snprintf(l, sizeof l,
                  "GRIP_DIAG book %d (h %.3f d %.3f): TCP above the book's bottom %.4f, behind its fore-edge %.4f, "
                  "off its middle %.4f; TCP above the upper shelf %.4f; book up-axis z %.3f; book turned in the "
                  "plates about the gripper's x/y/z %.1f %.1f %.1f deg",
                  target_book_id, h, d, in_book.z() + h / 2, in_book.x() + d / 2, in_book.y(), in_cart.z(),
                  pose.linear()(2, 2), rv.x(), rv.y(), rv.z());
    trace(l);
  }

  void on_gp(const lcm::ReceiveBuffer*, const std::string&, const grasp_point_t* m) {
    const std::string word = m->reason.substr(0, m->reason.find_first_of(" :"));
    if (m->reason != last_gp_reason) trace("GRASP_POINT " + m->reason.substr(0, 200));
    last_gp_reason = m->reason;
    if (word == "P1_VALID" || word == "P1_INVALID") {
      // Where the upper shelf's right-most corner really is against P1 and PS (a book pushed back shows as its Z).
      const ground_truth_t gt = sim->world().model().ground_truth(sim->world().now_utime());
      const book_truth_t* tb = nullptr;
      for (const auto& b : gt.books)
        if (b.place == "upper_shelf" && b.rightmost) tb = &b;
      if (tb) {
        const Eigen::Vector3d c = true_grasp(vec3(tb->p1_base)) * 1e3;
        std::string l = fmt("TRUTH right-most corner (%.1f, ", c.x()) + fmt("%.1f, ", c.y()) + fmt("%.1f) mm", c.z());
        if (norm_finite(m->p1_grasp) > 0) {
          const Eigen::Vector3d e = vec3(m->p1_grasp) * 1e3 - c;
          l += fmt("; P1 - corner (%.1f, ", e.x()) + fmt("%.1f, ", e.y()) + fmt("%.1f) mm", e.z());
        }
        if (norm_finite(m->ps_grasp) > 0) l += fmt("; PS.y - corner.y %.1f mm", m->ps_grasp[1] * 1e3 - c.y());
        trace(l);
      }
      std::vector<Eigen::Vector3d> corners;  // the upper shelf's true corners, right-most first
      for (const auto& b : gt.books)
        if (b.place == "upper_shelf") corners.push_back(true_grasp(vec3(b.p1_base)) * 1e3);
      std::sort(corners.begin(), corners.end(), [](const auto& a, const auto& b) { return a.y() > b.y(); });
      std::string l = "TRUTH upper-shelf corners (x y z mm), right-most first:";
      for (std::size_t i = 0; i < corners.size() && i < 4; ++i)
        l += fmt(" (%.0f ", corners[i].x()) + fmt("%.0f ", corners[i].y()) + fmt("%.0f)", corners[i].z());
      trace(l);
    }
    if (word == "GRASP" && m->valid) {
      GraspDecisionRecord d;
      d.book_index = status.current_book;
      d.p1_present = norm_finite(m->p1_grasp) > 0;
      d.p1_grasp = vec3(m->p1_grasp);
      d.p2_grasp = vec3(m->p2_grasp);
      d.gp_grasp = vec3(m->gp_grasp);
      d.p1_valid = m->p1_used;
      const book_truth_t* tb = truth_book(sim->world().model().ground_truth(sim->world().now_utime()), target_book_id);
      if (tb) {
        d.truth_known = true;
        d.p1_true_grasp = true_grasp(vec3(tb->p1_base));
        const Eigen::Vector3d e = (d.gp_grasp - d.p1_true_grasp) * 1e3;
        trace(fmt("TRUTH GP - true corner (%.1f, ", e.x()) + fmt("%.1f, ", e.y()) + fmt("%.1f) mm", e.z()) +
              fmt(", book width %.1f mm", tb->width_m * 1e3));
        // Where the arm is sent: GP in base (through the arbiter's cart frame) against the true corner, true axes.
        d.gp_base_true_grasp = true_grasp(pose_to_isometry(m->gp_base).translation());
        const Eigen::Vector3d eb = (d.gp_base_true_grasp - d.p1_true_grasp) * 1e3;
        trace(fmt("TRUTH GP in base - true corner (%.1f, ", eb.x()) + fmt("%.1f, ", eb.y()) +
              fmt("%.1f) mm in the true grasp frame", eb.z()));
      }
      res.decisions.push_back(d);
    } else if (word == "BOOK_WIDTH") {
      // The width check's step (the arbiter may put other steps, e.g. a follow note, before it).
      for (const auto& st : m->steps)
        if (st.rule.find("book width") != std::string::npos) {
          book(status.current_book).measured_width_m = st.value_m;
          break;
        }
    }
  }

  void snapshot(const std::string& state) {
    if (o.snapshot_dir.empty()) return;
    const std::string base = o.snapshot_dir + "/" + fmt("%03.0f", snapshot_seq++) + "_" + state;
    cv::Mat bgr;
    if (have_hand) {
      cv::cvtColor(image_to_mat(last_hand.image), bgr, cv::COLOR_RGB2BGR);
      cv::imwrite(base + "_hand_raw.png", bgr);  // what the detectors saw, to re-run them offline
      if (last_stripe_f.utime == last_hand.utime && last_stripe_f.found) {
        const double* l = last_stripe_f.centre_line_px;
        cv::line(bgr, cv::Point2d(l[0], l[1]), cv::Point2d(l[2], l[3]), cv::Scalar(255, 255, 0), 1);
        if (last_stripe_f.end_found)
          cv::drawMarker(bgr, cv::Point2d(last_stripe_f.end_px[0], last_stripe_f.end_px[1]), cv::Scalar(255, 255, 0),
                         cv::MARKER_CROSS, 16, 2);
      }
      if (last_book_f.utime == last_hand.utime && last_book_f.found)
        cv::drawMarker(bgr, cv::Point2d(last_book_f.r_px[0], last_book_f.r_px[1]), cv::Scalar(0, 0, 255),
                       cv::MARKER_CROSS, 16, 2);
      cv::imwrite(base + "_hand.png", bgr);
    }
    if (have_stereo && (state == "WAIT_P1_CHECK" || state == "MOVE_TO_HOLDER" || state == "WAIT_USER" ||
                        state == "DONE" || state == "ABORTED" || state == "MOVE_TO_LOWER_SHELF")) {
      cv::cvtColor(image_to_mat(last_stereo.left), bgr, cv::COLOR_RGB2BGR);
      cv::imwrite(base + "_stereo.png", bgr);
    }
  }

  /// Verbose: the held book against the holder (true support frame) while it is placed.
  int64_t last_holder_diag = 0;
  void holder_diag() {
    const auto& model = sim->world().model();
    const mjModel* mm = model.model();
    const mjData* dd = model.data();
    const int body = mj_name2id(mm, mjOBJ_BODY, ("book_" + std::to_string(target_book_id)).c_str());
    const int site = mj_name2id(mm, mjOBJ_SITE, "gripper");
    if (body < 0 || site < 0) return;
    const Eigen::Isometry3d inv = scene.holder_support_pose.inverse();
    const Eigen::Isometry3d pose = body_pose(dd, body);
    const Eigen::Vector3d b = inv * pose.translation();
    const Eigen::Vector3d tcp = inv * site_position(dd, site);
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = Eigen::Vector3d::Constant(-1e9);
    for (const auto& bk : scene.books)
      if (bk.id == target_book_id)
        for (const auto& c : scene::book_corners(pose, bk.width_m, bk.height_m, bk.depth_m)) {
          lo = lo.cwiseMin(inv * c);
          hi = hi.cwiseMax(inv * c);
        }
    // The book's extent in the support frame, then what it touches.
    std::string contacts = fmt(" extent x [%.3f", lo.x()) + fmt(" %.3f]", hi.x()) + fmt(" y [%.3f", lo.y()) +
                           fmt(" %.3f]", hi.y()) + fmt(" z [%.3f", lo.z()) + fmt(" %.3f]; contacts:", hi.z());
    for (int i = 0; i < dd->ncon; ++i) {
      const mjContact& c = dd->contact[i];
      const int b1 = mm->geom_bodyid[c.geom1], b2 = mm->geom_bodyid[c.geom2];
      if (b1 != body && b2 != body) continue;
      const int other = b1 == body ? c.geom2 : c.geom1;
      const char* n = mj_id2name(mm, mjOBJ_GEOM, other);
      contacts += std::string(" ") + (n ? n : "?") + fmt("(%.4f)", c.dist);
    }
    char l[400];
    std::snprintf(l, sizeof l,
                  "HOLDER_DIAG %s book id %d centre in support (%.3f %.3f %.3f) tcp (%.3f %.3f %.3f) width %.4f "
                  "gripper x/y/z up %.2f %.2f %.2f;",
                  status.state.c_str(), target_book_id, b.x(), b.y(), b.z(), tcp.x(), tcp.y(), tcp.z(),
                  model.gripper_width(), dd->site_xmat[9 * site + 6], dd->site_xmat[9 * site + 7],
                  dd->site_xmat[9 * site + 8]);
    trace(l + contacts);
  }

  /// "; book N base y [lo hi] ..., TCP (x y z)": where the books are across the shelves (base y) and the TCP.
  std::string book_extents_y(const mjData* dd, const std::vector<int>& ids) const {
    const mjModel* mm = sim->world().model().model();
    std::string l = ";";
    for (const int id : ids) {
      const int body = mj_name2id(mm, mjOBJ_BODY, ("book_" + std::to_string(id)).c_str());
      if (body < 0) continue;
      double lo = 1e9, hi = -1e9;
      for (const auto& bk : scene.books)
        if (bk.id == id)
          for (const auto& c : scene::book_corners(body_pose(dd, body), bk.width_m, bk.height_m, bk.depth_m)) {
            lo = std::min(lo, c.y());
            hi = std::max(hi, c.y());
          }
      l += " book " + std::to_string(id) + fmt(" base y [%.4f", lo) + fmt(" %.4f],", hi);
    }
    const int site = mj_name2id(mm, mjOBJ_SITE, "gripper");
    if (site >= 0) {
      const Eigen::Vector3d tcp = site_position(dd, site);
      l += fmt(" TCP (%.3f", tcp.x()) + fmt(" %.3f", tcp.y()) + fmt(" %.3f)", tcp.z());
    }
    return l;
  }

  /// Verbose: a robot geom touching a book that the gripper is not meant to hold (every pair once per task
  /// state entered): before the grasp any such touch is a collision, e.g. a servo pose's plates pushing the
  /// right-most book over.
  std::set<std::string> touches_seen;
  std::string touches_state;
  void touch_diag() {
    if (status.state != touches_state) {
      touches_state = status.state;
      touches_seen.clear();
    }
    const auto& model = sim->world().model();
    const mjModel* mm = model.model();
    const mjData* dd = model.data();
    const bool before_grasp = status.state == "SERVO_BOOK" || status.state == "MOVE_TO_BWH_START" ||
                              status.state == "SERVO_STRIPE" || status.state == "MOVE_TO_STRIPE_START" ||
                              status.state == "MOVE_TO_PRE_GRASP";
    for (int i = 0; i < dd->ncon; ++i) {
      const mjContact& c = dd->contact[i];
      int robot = c.geom1, book = c.geom2;
      if (model.geom_owner_id(book) < 0) std::swap(robot, book);
      const int b = model.geom_owner_id(book), r = model.geom_owner_id(robot);
      // The held book touching another book off the upper shelf: placing it pushes the ones placed before.
      if (target_book_id >= 0 && b >= 0 && r >= 0 && (b == target_book_id) != (r == target_book_id) &&
          status.state.find("LOWER_SHELF") != std::string::npos) {
        const int other = b == target_book_id ? r : b;
        const std::string key = "held book " + std::to_string(target_book_id) + " book " + std::to_string(other);
        if (touches_seen.insert(key).second)
          trace("TOUCH_DIAG " + status.state + ": " + key + fmt(" (dist %.4f m,", c.dist) + fmt(" at %.3f", c.pos[0]) +
                fmt(" %.3f", c.pos[1]) + fmt(" %.3f)", c.pos[2]) + book_extents_y(dd, {target_book_id, other}));
        continue;
      }
      if (b < 0 || (r != scene::kOwnerRobotArm && r != scene::kOwnerGripperFinger)) continue;
      if (!before_grasp && b == target_book_id) continue;  // inserting, holding, placing: its own book
      const char* rn = mj_id2name(mm, mjOBJ_GEOM, robot);
      const std::string key = std::string(rn ? rn : "?") + " book " + std::to_string(b);
      if (!touches_seen.insert(key).second) continue;
      trace("TOUCH_DIAG " + status.state + ": " + key + fmt(" (dist %.4f m)", c.dist));
    }
  }

  int64_t last_periodic = 0;
  std::string last_end;
  void step() {
    t += step_us;
    sim->advance_to(t);
    comp.spin();
    if (o.verbose) touch_diag();
    if (o.verbose && (status.state == "PLACE_ON_HOLDER" || status.state == "RELEASE_ON_HOLDER") &&
        t - last_holder_diag >= 200000) {
      last_holder_diag = t;
      holder_diag();
    }
    // The held book turning in the plates (MuJoCo's soft friction lets it creep about the finger axis).
    if (o.verbose && target_book_id >= 0 && (status.state == "EXTRACT" || status.state == "MOVE_TO_HOLDER") &&
        t - last_holder_diag >= 1000000) {
      last_holder_diag = t;
      grip_diag();
    }
    if (o.snapshot_period_s > 0 && (status.state == "SERVO_STRIPE" || status.state == "SERVO_BOOK") &&
        t - last_periodic >= static_cast<int64_t>(o.snapshot_period_s * 1e6)) {
      last_periodic = t;
      snapshot(status.state + fmt("_t%.1f", rel_s(t)));
    }
  }

  FullCycleResult result() const {
    FullCycleResult r = res;
    r.final_truth = sim->world().model().ground_truth(sim->world().now_utime());
    r.sim_s = rel_s(t);
    r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    r.message = status.message;
    r.end = last_end;
    return r;
  }
};

FullCycleHarness::FullCycleHarness(const FullCycleOptions& options) : impl_(std::make_unique<Impl>(options)) {}
FullCycleHarness::~FullCycleHarness() = default;

void FullCycleHarness::step() {
  impl_->step();
}

std::string FullCycleHarness::run_until(double budget_s, int max_books, const std::function<bool()>& stop) {
  const int64_t end = impl_->t + static_cast<int64_t>(budget_s * 1e6);
  std::string& word = impl_->last_end;
  word = "BUDGET";
  while (impl_->t < end) {
    impl_->step();
    const std::string& s = impl_->status.state;
    if (s == "DONE" || s == "ABORTED") return word = s;
    if (max_books > 0 && impl_->status.books_moved >= max_books) return word = "BOOKS";
    if (stop && stop()) return word = "STOP";
  }
  return word;
}

void FullCycleHarness::restart_coordinator() {
  impl_->restart_coordinator();
}
const task_status_t& FullCycleHarness::status() const {
  return impl_->status;
}
const ground_truth_t& FullCycleHarness::truth() const {
  return impl_->truth;
}
double FullCycleHarness::sim_time_s() const {
  return impl_->rel_s(impl_->t);
}
FullCycleResult FullCycleHarness::result() const {
  return impl_->result();
}
cv::Mat FullCycleHarness::last_stereo_left() const {
  return impl_->have_stereo ? image_to_mat(impl_->last_stereo.left).clone() : cv::Mat();
}
cv::Mat FullCycleHarness::last_hand_image() const {
  return impl_->have_hand ? image_to_mat(impl_->last_hand.image).clone() : cv::Mat();
}

FullCycleResult run_full_cycle(const FullCycleOptions& options, double budget_s, int max_books) {
  try {
    FullCycleHarness h(options);
    const std::string end = h.run_until(budget_s, max_books);
    FullCycleResult r = h.result();
    r.end = end;
    return r;
  } catch (const ConfigError&) {
    throw;  // the same for every seed: not this scene's result
  } catch (const std::exception& e) {
    FullCycleResult r;
    r.end = "ERROR";
    r.message = e.what();
    return r;
  }
}

}  // namespace bookgrasp
