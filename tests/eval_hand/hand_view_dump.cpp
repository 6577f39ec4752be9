// Debug tool: renders the hand camera at the converged corner pose (and at station B) of
// seeded scenes, runs BwH and BSwH on the image and writes the raw image and an overlay
// (truth: green = right-most P1, yellow = other P1, magenta = stripe end; detections:
// red = R of the chosen book, orange = other candidates' R, cyan = stripe end).
// Usage: hand_view_dump OUT_DIR FIRST_SEED COUNT [dx dy]
//        hand_view_dump --stripe OUT_DIR FIRST_SEED COUNT: the stripe servo from station A; the converged
//        (last) hand image as <seed>_stripe_raw.png and the projected true stripe end printed.
//        hand_view_dump --stripe-start OUT_DIR FIRST_SEED COUNT: the hand image at station A and the visible
//        stripe end there (the right-most book's projected silhouette at the stripe row).
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "bookgrasp/servo_request_t.hpp"
#include "common/config.h"
#include "services/bswh_detector/stripe_detection.h"
#include "services/bwh_detector/book_detection_hand.h"
#include "services/bwh_detector/page_face_detection.h"
#include "services/eval_hand/hand_servo_harness.h"

using namespace bookgrasp;

namespace {

int stripe_dump(const std::string& out, int first, int count, bool start_only) {
  std::filesystem::create_directories(out);
  const std::string src = BOOKGRASP_SOURCE_DIR;
  HandServoOptions o;
  o.config_dir = src + "/config/services";
  for (int seed = first; seed < first + count; ++seed) {
    const scene::Scene s = scene::load_scene(src + "/services/eval_hand/scenes/hand_eval.yaml", seed);
    HandServoTask task;
    task.mode = servo_request_t::STRIPE_END;
    const Eigen::Vector3d a(0.10, 0.30, -0.10);
    task.standoff_m = s.shelf_depth_m - a.z();
    task.timeout_s = 20;
    task.start_tcp = cart_grasp_pose(s, a);
    if (start_only) task.timeout_s = 0.05;  // the view at station A
    const HandServoResult r = run_hand_servo_task(s, task, o);
    if (r.last_image.empty()) continue;
    if (start_only) {
      // The visible end at A: the right-most book's silhouette (convex hull of its projected corners)
      // at the stripe's row (the TCP is at stripe height: the row of the projected true end).
      const double f = 240.0 / std::tan(29.0 * M_PI / 180.0);
      auto proj = [&](const double* p) {
        const Eigen::Vector3d c = r.last_camera_in_base.inverse() * Eigen::Vector3d(p[0], p[1], p[2]);
        return cv::Point2f(static_cast<float>(319.5 + f * c.x() / c.z()),
                           static_cast<float>(239.5 + f * c.y() / c.z()));
      };
      const double v = proj(r.truth.stripe_end_base).y;
      double u = -1;
      for (const auto& b : r.truth.books) {
        if (!b.rightmost) continue;
        std::vector<cv::Point2f> pts, hull;
        for (const auto& c : b.corners_base) pts.push_back(proj(c));
        cv::convexHull(pts, hull);
        for (size_t i = 0; i < hull.size(); ++i) {
          const cv::Point2f a = hull[i], c = hull[(i + 1) % hull.size()];
          if ((a.y - v) * (c.y - v) > 0 || a.y == c.y) continue;
          u = std::max(u, a.x + (v - a.y) * (c.x - a.x) / (c.y - a.y));
        }
      }
      cv::Mat bgr;
      cv::cvtColor(r.last_image, bgr, cv::COLOR_RGB2BGR);
      char name[64];
      std::snprintf(name, sizeof(name), "seed%03d_station_a_raw.png", seed);
      cv::imwrite(out + "/" + name, bgr);
      std::printf("seed %d at A: visible stripe end (book silhouette) at (%.2f, %.2f) px\n", seed, u, v);
      continue;
    }
    cv::Mat bgr;
    cv::cvtColor(r.last_image, bgr, cv::COLOR_RGB2BGR);
    char name[64];
    std::snprintf(name, sizeof(name), "seed%03d_stripe_raw.png", seed);
    cv::imwrite(out + "/" + name, bgr);
    const double f = 240.0 / std::tan(29.0 * M_PI / 180.0);
    const Eigen::Vector3d c =
        r.last_camera_in_base.inverse() *
        Eigen::Vector3d(r.truth.stripe_end_base[0], r.truth.stripe_end_base[1], r.truth.stripe_end_base[2]);
    std::printf("seed %d: state %d, true stripe end at (%.2f, %.2f) px, BSwH end %d (%.2f, %.2f)\n", seed, r.state,
                319.5 + f * c.x() / c.z(), 239.5 + f * c.y() / c.z(), r.last_stripe_end_found ? 1 : 0,
                r.last_stripe_end_px.x(), r.last_stripe_end_px.y());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 5 && std::string(argv[1]) == "--stripe")
    return stripe_dump(argv[2], std::stoi(argv[3]), std::stoi(argv[4]), false);
  if (argc >= 5 && std::string(argv[1]) == "--stripe-start")
    return stripe_dump(argv[2], std::stoi(argv[3]), std::stoi(argv[4]), true);
  if (argc < 4) {
    std::cerr << "usage: hand_view_dump OUT_DIR FIRST_SEED COUNT [dx dy]\n";
    return 2;
  }
  const std::string out = argv[1];
  const int first = std::stoi(argv[2]), count = std::stoi(argv[3]);
  const double dx = argc > 5 ? std::stod(argv[4]) : 0.0, dy = argc > 5 ? std::stod(argv[5]) : 0.0;
  std::filesystem::create_directories(out);
  const std::string src = BOOKGRASP_SOURCE_DIR;
  const Config bwh_cfg = Config::load_file(src + "/config/services/bwh_detector.yaml");
  const BookDetectionParams bp = BookDetectionParams::from_config(bwh_cfg.child("books"));
  HandServoOptions o;
  o.config_dir = src + "/config/services";
  const double f = 240.0 / std::tan(29.0 * M_PI / 180.0);
  for (int seed = first; seed < first + count; ++seed) {
    const scene::Scene s = scene::load_scene(src + "/services/eval_hand/scenes/hand_eval.yaml", seed);
    const ground_truth_t t0 = scene_truth(s);
    HandServoTask task;
    task.mode = servo_request_t::BOOK_CORNER;
    task.standoff_m = 0.22;
    task.timeout_s = 0.05;
    task.start_tcp = *corner_start(s, t0, dx, dy, task.standoff_m);
    const HandServoResult r = run_hand_servo_task(s, task, o);
    if (!r.ik_ok || r.last_image.empty()) {
      std::cout << "seed " << seed << ": no image (" << r.ik_message << ")\n";
      continue;
    }
    cv::Mat bgr;
    cv::cvtColor(r.last_image, bgr, cv::COLOR_RGB2BGR);
    char name[64];
    std::snprintf(name, sizeof(name), "seed%03d", seed);
    cv::imwrite(out + "/" + name + "_raw.png", bgr);
    const BookDetection d = std::getenv("OLD") ? detect_books_hand(r.last_image, bp)
                                               : detect_books_page_faces(r.last_image, PageFaceParams{});
    auto proj = [&](const double* p, cv::Point2d* px) {
      const Eigen::Vector3d c = r.last_camera_in_base.inverse() * Eigen::Vector3d(p[0], p[1], p[2]);
      if (c.z() <= 0) return false;
      *px = cv::Point2d(319.5 + f * c.x() / c.z(), 239.5 + f * c.y() / c.z());
      return true;
    };
    cv::Point2d px, truth_r(-1, -1);
    for (const auto& b : r.truth.books) {
      if (b.place != "upper_shelf") continue;
      if (proj(b.p1_base, &px)) {
        cv::circle(bgr, px, b.rightmost ? 6 : 4, b.rightmost ? cv::Scalar(0, 255, 0) : cv::Scalar(0, 220, 255), 1);
        if (b.rightmost) truth_r = px;
      }
    }
    for (const auto& c : d.candidates) {
      cv::rectangle(bgr, c.bbox, c.accepted ? cv::Scalar(0, 160, 255) : cv::Scalar(120, 120, 120), 1);
      cv::drawMarker(bgr, c.corner_r, cv::Scalar(0, 128, 255), cv::MARKER_TILTED_CROSS, 8, 1);
    }
    std::string chosen = "none";
    if (d.found) {
      const auto& b = d.candidates[static_cast<size_t>(d.ranking[0])];
      cv::drawMarker(bgr, b.corner_r, cv::Scalar(0, 0, 255), cv::MARKER_CROSS, 16, 2);
      char buf[128];
      std::snprintf(buf, sizeof(buf), "R (%.1f, %.1f) err %.1f px", b.corner_r.x, b.corner_r.y,
                    cv::norm(b.corner_r - truth_r));
      chosen = buf;
    }
    cv::imwrite(out + "/" + name + "_overlay.png", bgr);
    std::cout << "seed " << seed << ": truth R (" << truth_r.x << ", " << truth_r.y << ") " << chosen << " ["
              << d.failure_reason << "]\n";
    for (const auto& c : d.candidates)
      std::cout << "   cand " << c.id << " bbox " << c.bbox << " R " << c.corner_r << " w " << c.width_px << " h "
                << c.height_px << " fill " << c.fill_ratio << " merged " << c.num_merged << " "
                << (c.accepted ? "ACCEPTED" : c.reject_reason) << "\n";
  }
}
