#include "services/eval_bws/bws_scene_eval.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>

#include <opencv2/imgproc.hpp>

#include "bookgrasp/marker_detections_t.hpp"
#include "common/image_caption.h"
#include "common/image_conversion.h"
#include "common/pose_conversion.h"
#include "common/sim_render/sim_camera_rig.h"
#include "services/bws_detector/bws_detector_node.h"
#include "services/bws_detector/cart_geometry.h"
#include "services/bws_detector/debug_overlay.h"
#include "services/marker_detector/marker_detector_node.h"

namespace bookgrasp::eval_bws {

RenderedScene render_scene(sim_render::SimCameraRig& rig, int64_t utime) {
  const sim_render::CameraImage left = rig.capture("stereo_left", utime, /*with_depth=*/false, /*with_owner=*/true);
  const sim_render::CameraImage right = rig.capture("stereo_right", utime);
  RenderedScene s;
  stereo_frame_t& f = s.frame;
  f.utime = utime;
  f.sequence = 0;
  f.left = mat_to_image(left.rgb, image_t::RGB8, utime, left.camera.frame);
  f.right = mat_to_image(right.rgb, image_t::RGB8, utime, right.camera.frame);
  f.left_calibration = left.camera.to_message(utime);
  f.right_calibration = right.camera.to_message(utime);
  f.baseline_m = (left.camera.camera_in_base.translation() - right.camera.camera_in_base.translation()).norm();
  s.owner = left.owner;
  s.left_camera = left.camera;
  s.truth = rig.model().ground_truth(utime);
  return s;
}

SceneResult evaluate_scene(const RenderedScene& scene, uint64_t seed, MarkerDetectorNode& markers, BwsDetectorNode& bws,
                           cv::Mat* overlay) {
  SceneResult r;
  r.seed = seed;
  const ground_truth_t& t = scene.truth;
  const book_truth_t* right = nullptr;
  for (const book_truth_t& b : t.books)
    if (b.rightmost) right = &b;
  if (!right) {
    r.failure = "scene has no right-most book (truth)";
    return r;
  }
  r.rightmost_id = right->id;
  r.rightmost_width_m = right->width_m;

  marker_detections_t md;
  std::string why;
  if (!markers.process(scene.frame, &md, &why)) {
    r.failure = "marker detector: " + why;
    return r;
  }
  bool has_cart = false;
  std::string ids;
  for (const marker_t& m : md.markers) {
    ids += " " + std::to_string(m.id) + (m.role.empty() ? "" : "(" + m.role + ")");
    if (m.role != "cart" || has_cart) continue;
    has_cart = true;
    // The scene's marker frame has y up and z towards the robot; AprilTag's has y down, z into the tag.
    Eigen::Isometry3d truth = pose_to_isometry(t.cart_marker);
    truth.linear() = truth.linear() * Eigen::Vector3d(1, -1, -1).asDiagonal();
    const Eigen::Isometry3d found = pose_to_isometry(m.pose_in_base);
    r.cart_marker_found = true;
    r.cart_marker_angle_deg = Eigen::AngleAxisd(found.linear().transpose() * truth.linear()).angle() * 180.0 / M_PI;
    r.cart_marker_position_mm = (found.translation() - truth.translation()).norm() * 1000.0;
  }
  if (!has_cart) {
    r.failure = "marker detector found no cart marker (" + std::to_string(md.num_markers) + " markers:" + ids + ")";
    if (overlay) {
      *overlay = image_to_mat(scene.frame.left).clone();
      draw_caption(overlay, 0, "seed " + std::to_string(seed) + ": " + r.failure, cv::Scalar(255, 80, 80));
    }
    return r;
  }
  why = bws.take_markers(md);
  if (!why.empty()) {
    r.failure = "markers refused: " + why;
    return r;
  }
  book_corner_stereo_t out;
  why = bws.process(scene.frame, &out, nullptr);
  if (!why.empty()) {
    r.failure = "frame rejected: " + why;
    return r;
  }
  r.disparity_ms = out.disparity_ms;
  r.segmentation_ms = out.segmentation_ms;
  r.total_ms = out.total_ms;
  const bws::BwsOutput& o = bws.last_output();
  if (overlay) {
    char title[64];
    std::snprintf(title, sizeof title, "%s seed %llu", out.implementation.c_str(), (unsigned long long)seed);
    *overlay = bws::draw_bws_overlay(image_to_mat(scene.frame.left), o, title);
    // The true P1 of the right-most book: a cyan ring (the detector's P1 is the yellow cross).
    const Eigen::Vector3d truth_p1(right->p1_base[0], right->p1_base[1], right->p1_base[2]);
    if (scene.left_camera.to_camera(truth_p1).z() > 0.0) {
      const Eigen::Vector2d px = scene.left_camera.project(truth_p1);
      cv::circle(*overlay, {int(std::lround(px.x())), int(std::lround(px.y()))}, 4, cv::Scalar(0, 255, 255), 1,
                 cv::LINE_AA);
    }
  }
  if (!out.found) {
    r.failure = "no P1: " + out.failure_reason;
    return r;
  }
  r.found = true;
  r.top_crease_shift_m = o.selection.top_crease_shift_m;
  // Which book the corner was found on: the owner of most of the selected region's pixels within
  // kCornerWindow px of PI (and in the selected column band when the region was split).
  constexpr int kCornerWindow = 6;
  std::map<int, int> votes;
  const cv::Point pi = o.selection.pi;
  for (int y = std::max(0, pi.y - kCornerWindow); y <= std::min(o.segmentation.labels.rows - 1, pi.y + kCornerWindow);
       ++y) {
    const int* l = o.segmentation.labels.ptr<int>(y);
    const int* w = scene.owner.ptr<int>(y);
    for (int x = std::max(0, pi.x - kCornerWindow); x <= std::min(o.segmentation.labels.cols - 1, pi.x + kCornerWindow);
         ++x) {
      // PI moved onto the front layer lies outside the selected region: every pixel near it votes.
      if (!o.selection.pi_from_layer) {
        if (l[x] != out.selected_label) continue;
        if (o.selection.split && (x < o.selection.band_x0 || x > o.selection.band_x1)) continue;
      }
      ++votes[w[x]];
    }
  }
  int best = 0;
  for (const auto& [owner, n] : votes)
    if (n > best) {
      best = n;
      r.selected_owner = owner;
    }
  const Eigen::Isometry3d grasp_true = bws::grasp_frame_of_cart(pose_to_isometry(t.cart));
  const Eigen::Vector3d p1(out.p1_base[0], out.p1_base[1], out.p1_base[2]);
  const Eigen::Vector3d truth(right->p1_base[0], right->p1_base[1], right->p1_base[2]);
  r.error_grasp = grasp_true.linear().transpose() * (p1 - truth);
  // Wrong book: the found corner is nearer to another upper-shelf book's true P1 than to the right-most's.
  int nearest = -1;
  double nearest_d = std::numeric_limits<double>::infinity();
  for (const book_truth_t& b : t.books) {
    if (b.place != "upper_shelf") continue;
    const double d = (p1 - Eigen::Vector3d(b.p1_base[0], b.p1_base[1], b.p1_base[2])).norm();
    if (d < nearest_d) {
      nearest_d = d;
      nearest = b.id;
    }
  }
  if (nearest != right->id) {
    r.wrong_book = true;
    r.failure = "wrong book: P1 is nearest to book " + std::to_string(nearest) + "'s corner; " +
                (o.selection.pi_from_layer ? "the pixels at PI (front layer) lie on " : "region at PI lies on ") +
                (r.selected_owner >= 0 ? "book " + std::to_string(r.selected_owner)
                                       : "owner code " + std::to_string(r.selected_owner)) +
                ", right-most is book " + std::to_string(right->id) + " (P1 error grasp mm " +
                std::to_string(int(std::lround(r.error_grasp(0) * 1000))) + " " +
                std::to_string(int(std::lround(r.error_grasp(1) * 1000))) + " " +
                std::to_string(int(std::lround(r.error_grasp(2) * 1000))) + ")";
  }
  return r;
}

Stats stats_of(std::vector<double> v) {
  Stats s;
  if (v.empty()) {
    s.mean = s.median = s.max = std::numeric_limits<double>::quiet_NaN();
    return s;
  }
  std::sort(v.begin(), v.end());
  double sum = 0;
  for (double x : v) sum += x;
  s.mean = sum / double(v.size());
  const size_t n = v.size();
  s.median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  s.max = v.back();
  return s;
}

namespace {
std::string num(double v, int prec = 3) {
  if (!std::isfinite(v)) return "null";
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", prec, v);
  return b;
}
std::string stats_json(const Stats& s, int prec = 3) {
  return "{\"mean\": " + num(s.mean, prec) + ", \"median\": " + num(s.median, prec) + ", \"max\": " + num(s.max, prec) +
         "}";
}
/// A cart marker pose further than this from the truth is a flipped (ambiguous) solution.
constexpr double kFlippedMarkerDeg = 10.0;
/// The paper's tolerances between P1 and P2 (Section 4.1): the hand camera's search starts from P1.
constexpr double kToleranceXmm = 20.0, kToleranceYmm = 15.0;
/// A P1 on the right book but further than this from its corner on some axis (a region beside the book).
constexpr double kFarOffMm = 50.0;
struct Summary {
  int scenes = 0, found = 0, wrong = 0, failures = 0, correct = 0;
  int within_tolerance = 0, far_off = 0;
  int creased = 0;  // scenes with a P1 whose height came from the top's crease
  int markers_found = 0, markers_flipped = 0;
  Stats marker_angle, marker_position;
  Stats err[3], bias[3];
  Stats disp, seg, total;
};
Summary summarize(const std::vector<SceneResult>& rs) {
  Summary s;
  std::vector<double> e[3], b[3], d, g, t, ma, mp;
  for (const SceneResult& r : rs) {
    ++s.scenes;
    if (r.cart_marker_found) {
      ++s.markers_found;
      s.markers_flipped += r.cart_marker_angle_deg > kFlippedMarkerDeg;
      ma.push_back(r.cart_marker_angle_deg);
      mp.push_back(r.cart_marker_position_mm);
    }
    s.found += r.found;
    s.wrong += r.wrong_book;
    s.creased += r.found && std::isfinite(r.top_crease_shift_m);
    if (!r.found || r.wrong_book) ++s.failures;
    if (r.found && !r.wrong_book) {
      ++s.correct;
      const Eigen::Vector3d mm = r.error_grasp * 1000.0;
      s.within_tolerance += std::fabs(mm.x()) <= kToleranceXmm && std::fabs(mm.y()) <= kToleranceYmm;
      s.far_off += mm.cwiseAbs().maxCoeff() > kFarOffMm;
      for (int i = 0; i < 3; ++i) {
        e[i].push_back(std::fabs(r.error_grasp(i)) * 1000.0);
        b[i].push_back(r.error_grasp(i) * 1000.0);
      }
    }
    if (r.total_ms > 0) {
      d.push_back(r.disparity_ms);
      g.push_back(r.segmentation_ms);
      t.push_back(r.total_ms);
    }
  }
  for (int i = 0; i < 3; ++i) {
    s.err[i] = stats_of(e[i]);
    s.bias[i] = stats_of(b[i]);
  }
  s.marker_angle = stats_of(ma);
  s.marker_position = stats_of(mp);
  s.disp = stats_of(d);
  s.seg = stats_of(g);
  s.total = stats_of(t);
  return s;
}
}  // namespace

std::string metrics_json(const std::vector<SceneResult>& rs, const std::string& impl, const std::string& scene_file,
                         uint64_t first_seed) {
  const Summary s = summarize(rs);
  std::ostringstream j;
  j << "{\n  \"implementation\": \"" << impl << "\",\n  \"scene_file\": \"" << scene_file << "\",\n"
    << "  \"first_seed\": " << first_seed << ",\n  \"scenes\": " << s.scenes << ",\n  \"found\": " << s.found
    << ",\n  \"failures\": " << s.failures << ",\n  \"no_p1\": " << (s.scenes - s.found)
    << ",\n  \"wrong_book\": " << s.wrong << ",\n  \"correct\": " << s.correct
    << ",\n  \"within_tolerance\": " << s.within_tolerance
    << ",\n  \"within_tolerance_mm\": {\"x\": " << num(kToleranceXmm, 1) << ", \"y\": " << num(kToleranceYmm, 1)
    << "},\n  \"top_crease_applied\": " << s.creased << ",\n  \"far_off\": " << s.far_off
    << ",\n  \"far_off_above_mm\": " << num(kFarOffMm, 1) << ",\n"
    << "  \"p1_error_mm\": {\"frame\": \"grasp (X up, Y right, Z into the shelf), |estimate - truth| over correct "
       "scenes\",\n"
    << "    \"x\": " << stats_json(s.err[0]) << ",\n    \"y\": " << stats_json(s.err[1])
    << ",\n    \"z\": " << stats_json(s.err[2]) << "},\n"
    << "  \"p1_bias_mm\": {\"x\": " << stats_json(s.bias[0]) << ", \"y\": " << stats_json(s.bias[1])
    << ", \"z\": " << stats_json(s.bias[2]) << "},\n"
    << "  \"ms_per_frame\": {\"disparity\": " << stats_json(s.disp, 2) << ", \"segmentation\": " << stats_json(s.seg, 2)
    << ", \"total\": " << stats_json(s.total, 2) << "},\n"
    << "  \"cart_marker\": {\"found\": " << s.markers_found << ", \"flipped\": " << s.markers_flipped
    << ", \"flipped_above_deg\": " << num(kFlippedMarkerDeg, 1) << ", \"angle_deg\": " << stats_json(s.marker_angle, 2)
    << ", \"position_mm\": " << stats_json(s.marker_position, 1) << "},\n  \"per_scene\": [\n";
  for (size_t i = 0; i < rs.size(); ++i) {
    const SceneResult& r = rs[i];
    j << "    {\"seed\": " << r.seed << ", \"found\": " << (r.found ? "true" : "false")
      << ", \"wrong_book\": " << (r.wrong_book ? "true" : "false") << ", \"error_mm\": ["
      << num(r.error_grasp(0) * 1000, 2) << ", " << num(r.error_grasp(1) * 1000, 2) << ", "
      << num(r.error_grasp(2) * 1000, 2)
      << "], \"cart_marker_angle_deg\": " << (r.cart_marker_found ? num(r.cart_marker_angle_deg, 2) : "null")
      << ", \"rightmost_width_mm\": " << num(r.rightmost_width_m * 1000, 1)
      << ", \"top_crease_shift_mm\": " << num(r.top_crease_shift_m * 1000, 2)
      << ", \"total_ms\": " << num(r.total_ms, 2) << ", \"failure\": \"";
    for (char c : r.failure) j << (c == '"' || c == '\\' ? '\'' : c);
    j << "\"}" << (i + 1 < rs.size() ? "," : "") << "\n";
  }
  j << "  ]\n}\n";
  return j.str();
}

std::string report_markdown(const std::vector<SceneResult>& rs, const std::string& impl, const std::string& command) {
  const Summary s = summarize(rs);
  std::ostringstream m;
  m << "# BwS evaluation (" << impl << ")\n\nCommand: `" << command << "`\n\n"
    << "Scenes: " << s.scenes << "; P1 found: " << s.found << "; wrong book: " << s.wrong
    << "; failures (no P1 or wrong book): " << s.failures << " (paper: 2 of 20). P1 on the right book within the "
    << "paper's P1-P2 tolerances (|X| <= " << num(kToleranceXmm, 0) << " mm, |Y| <= " << num(kToleranceYmm, 0)
    << " mm): " << s.within_tolerance << " of " << s.scenes << "; on the right book but more than " << num(kFarOffMm, 0)
    << " mm off on some axis: " << s.far_off << ".\n\n"
    << "P1 error |estimate - truth| in the true grasp frame (X up, Y right, Z into the shelf), mm, over the "
    << s.correct
    << " correct scenes:\n\n| axis | mean | median | max | signed mean (bias) | paper mean "
       "|\n|---|---|---|---|---|---|\n";
  const char* ax = "XYZ";
  const double paper[3] = {5.2, 11.7, 3.8};
  for (int i = 0; i < 3; ++i)
    m << "| " << ax[i] << " | " << num(s.err[i].mean, 2) << " | " << num(s.err[i].median, 2) << " | "
      << num(s.err[i].max, 2) << " | " << num(s.bias[i].mean, 2) << " | " << num(paper[i], 1) << " |\n";
  m << "\nCart marker (marker_detector against the true tag pose): found in " << s.markers_found << " of " << s.scenes
    << " scenes; rotation error median " << num(s.marker_angle.median, 2) << " deg, max " << num(s.marker_angle.max, 2)
    << " deg; " << s.markers_flipped << " flipped (> " << num(kFlippedMarkerDeg, 0)
    << " deg, the planar pose ambiguity); centre error median " << num(s.marker_position.median, 1) << " mm, max "
    << num(s.marker_position.max, 1) << " mm.\n";
  m << "\nWall time per frame, ms (machine shared, wall clock): disparity median " << num(s.disp.median, 1)
    << ", segmentation median " << num(s.seg.median, 1) << ", total median " << num(s.total.median, 1) << " (max "
    << num(s.total.max, 1) << ").\n\n![P1 error per scene](figure12.png)\n\n## Failed scenes\n\n";
  int listed = 0;
  for (const SceneResult& r : rs)
    if (!r.found || r.wrong_book) {
      m << "- seed " << r.seed << " (right-most book " << num(r.rightmost_width_m * 1000, 1)
        << " mm thick): " << r.failure << "\n";
      ++listed;
    }
  if (!listed) m << "None.\n";
  return m.str();
}

cv::Mat figure12_plot(const std::vector<SceneResult>& rs, const std::string& title) {
  const int W = 1200, H = 520, L = 70, R = 20, T = 50, B = 60;
  cv::Mat img(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
  double ymax = 5.0;
  for (const SceneResult& r : rs)
    if (r.found && !r.wrong_book)
      for (int i = 0; i < 3; ++i) ymax = std::max(ymax, std::fabs(r.error_grasp(i)) * 1000.0);
  ymax = std::ceil(std::min(ymax, 60.0) / 5.0) * 5.0;
  const int pw = W - L - R, ph = H - T - B;
  const auto ypix = [&](double v) { return T + ph - int(std::round(std::min(v, ymax) / ymax * ph)); };
  for (int k = 0; k <= 5; ++k) {
    const double v = ymax * k / 5;
    cv::line(img, {L, ypix(v)}, {W - R, ypix(v)}, cv::Scalar(225, 225, 225));
    cv::putText(img, num(v, 0), {L - 40, ypix(v) + 5}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1,
                cv::LINE_AA);
  }
  const cv::Scalar col[3] = {cv::Scalar(31, 119, 180), cv::Scalar(255, 127, 14), cv::Scalar(44, 160, 44)};
  const int n = std::max<int>(1, int(rs.size()));
  const double slot = double(pw) / n;
  for (int k = 0; k < int(rs.size()); ++k) {
    const SceneResult& r = rs[size_t(k)];
    const double x0 = L + k * slot;
    if (!r.found || r.wrong_book) {
      cv::rectangle(img, cv::Point(int(x0), T), cv::Point(int(x0 + slot) - 1, T + ph), cv::Scalar(255, 200, 200),
                    cv::FILLED);
      continue;
    }
    const double bw = std::max(1.0, slot / 3.5);
    for (int i = 0; i < 3; ++i) {
      const int xa = int(x0 + 0.25 * bw + i * bw), xb = std::max(xa, int(x0 + 0.25 * bw + (i + 1) * bw) - 1);
      cv::rectangle(img, cv::Point(xa, ypix(std::fabs(r.error_grasp(i)) * 1000.0)), cv::Point(xb, T + ph), col[i],
                    cv::FILLED);
    }
  }
  cv::rectangle(img, cv::Point(L, T), cv::Point(W - R, T + ph), cv::Scalar(0, 0, 0));
  cv::putText(img, title, {L, 30}, cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::putText(img, "|P1 error| mm", {5, T - 8}, cv::FONT_HERSHEY_SIMPLEX, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  const char* names[3] = {"X (up)", "Y (right)", "Z (into shelf)"};
  for (int i = 0; i < 3; ++i) {
    cv::rectangle(img, cv::Point(L + 10 + 150 * i, H - 30), cv::Point(L + 24 + 150 * i, H - 16), col[i], cv::FILLED);
    cv::putText(img, names[i], {L + 30 + 150 * i, H - 18}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1,
                cv::LINE_AA);
  }
  cv::rectangle(img, cv::Point(L + 460, H - 30), cv::Point(L + 474, H - 16), cv::Scalar(255, 200, 200), cv::FILLED);
  cv::putText(img, "failed (no P1 / wrong book)", {L + 480, H - 18}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0),
              1, cv::LINE_AA);
  cv::putText(img, "scene (seed order)", {W - R - 170, H - 18}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
  return img;
}

}  // namespace bookgrasp::eval_bws
