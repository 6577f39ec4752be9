#include "services/eval_hand/hand_eval_metrics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace bookgrasp {

HandStats hand_stats(std::vector<double> v) {
  HandStats s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  s.n = static_cast<int>(v.size());
  double sum = 0;
  for (double x : v) sum += x;
  s.mean = sum / s.n;
  s.min = v.front();
  s.max = v.back();
  s.median = s.n % 2 ? v[static_cast<size_t>(s.n / 2)]
                     : 0.5 * (v[static_cast<size_t>(s.n / 2 - 1)] + v[static_cast<size_t>(s.n / 2)]);
  s.p95 = v[static_cast<size_t>(std::min<double>(s.n - 1, std::ceil(0.95 * s.n) - 1))];
  return s;
}

void accumulate(const HandSceneOutcome& o, const HandTolerances& tol, HandEvalMetrics* m) {
  ++m->scenes;
  m->scene_wall_s.push_back(o.wall_s);
  m->bwh_ms.insert(m->bwh_ms.end(), o.bwh_ms.begin(), o.bwh_ms.end());
  m->bswh_ms.insert(m->bswh_ms.end(), o.bswh_ms.begin(), o.bswh_ms.end());
  m->markers_ms.insert(m->markers_ms.end(), o.markers_ms.begin(), o.markers_ms.end());
  const size_t failures_before = m->failures.size();
  if (!o.error.empty()) m->failures.push_back({o.seed, "scene", o.error});

  const HandTaskOutcome& s = o.stripe;
  if (s.run) {
    ++m->stripe_runs;
    if (s.converged) {
      ++m->stripe_converged;
      m->stripe_abs_mm[0].push_back(std::abs(s.error_x_m) * 1e3);
      m->stripe_abs_mm[1].push_back(std::abs(s.error_y_m) * 1e3);
      m->iterations.push_back(s.iterations);
      m->stripe_iterations.push_back(s.iterations);
      m->stripe_time_s.push_back(s.time_s);
      if (std::abs(s.error_x_m) <= tol.stripe_x_m && std::abs(s.error_y_m) <= tol.stripe_y_m) {
        ++m->stripe_within;
      } else {
        char b[160];
        std::snprintf(b, sizeof b, "stripe end error (%.1f, %.1f) mm (X, Y) outside the tolerance", s.error_x_m * 1e3,
                      s.error_y_m * 1e3);
        m->failures.push_back({o.seed, "stripe", b});
      }
    } else {
      m->failures.push_back({o.seed, "stripe", s.state + ": " + s.message});
    }
  } else if (o.error.empty()) {
    m->failures.push_back({o.seed, "stripe", "not run: " + s.message});
  }

  const HandTaskOutcome& c = o.corner;
  if (c.run) {
    ++m->corner_runs;
    if (c.converged) {
      ++m->corner_converged;
      m->p2_abs_mm[0].push_back(std::abs(c.error_x_m) * 1e3);
      m->p2_abs_mm[1].push_back(std::abs(c.error_y_m) * 1e3);
      m->p2_abs_mm[2].push_back(std::abs(c.error_z_m) * 1e3);
      m->slope_abs_deg.push_back(std::abs(c.slope_error_deg));
      m->iterations.push_back(c.iterations);
      m->corner_iterations.push_back(c.iterations);
      m->corner_time_s.push_back(c.time_s);
      if (std::abs(c.slope_error_deg) <= tol.slope_deg) ++m->slope_within;
      if (std::abs(c.error_x_m) <= tol.p2_x_m && std::abs(c.error_y_m) <= tol.p2_y_m) {
        ++m->corner_within;
      } else {
        char b[160];
        std::snprintf(b, sizeof b, "P2 - P1 (%.1f, %.1f) mm (X, Y) outside the grasping tolerance", c.error_x_m * 1e3,
                      c.error_y_m * 1e3);
        m->failures.push_back({o.seed, "corner", b});
      }
    } else {
      m->failures.push_back({o.seed, "corner", c.state + ": " + c.message});
    }
  } else if (o.error.empty()) {
    m->failures.push_back({o.seed, "corner", "not run: " + c.message});
  }
  if (m->failures.size() > failures_before) ++m->failed_scenes;
}

namespace {

std::string num(double v) {
  if (!std::isfinite(v)) return "null";
  char b[64];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

std::string rate(int k, int n) {
  return n > 0 ? num(static_cast<double>(k) / n) : "null";
}

std::string esc(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (c == '\n') {
      o += "\\n";
      continue;
    }
    if (static_cast<unsigned char>(c) < 0x20) continue;
    o += c;
  }
  return o;
}

std::string stats_json(const std::vector<double>& v) {
  const HandStats s = hand_stats(v);
  return "{\"n\": " + std::to_string(s.n) + ", \"mean\": " + num(s.mean) + ", \"median\": " + num(s.median) +
         ", \"p95\": " + num(s.p95) + ", \"max\": " + num(s.max) + "}";
}

}  // namespace

namespace {

std::string task_json(const HandTaskOutcome& t) {
  std::ostringstream j;
  j << "{\"state\": \"" << esc(t.state) << "\", \"converged\": " << (t.converged ? "true" : "false")
    << ", \"iterations\": " << t.iterations << ", \"time_s\": " << num(t.time_s);
  if (t.converged) {
    j << ", \"error_mm\": [" << num(t.error_x_m * 1e3) << ", " << num(t.error_y_m * 1e3) << ", "
      << num(t.error_z_m * 1e3) << "], \"slope_error_deg\": " << num(t.slope_error_deg) << ", \"tcp_base\": ["
      << num(t.tcp_base[0]) << ", " << num(t.tcp_base[1]) << ", " << num(t.tcp_base[2]) << "], \"truth_base\": ["
      << num(t.truth_base[0]) << ", " << num(t.truth_base[1]) << ", " << num(t.truth_base[2]) << "]";
  }
  j << "}";
  return j.str();
}

}  // namespace

std::string hand_metrics_json(const HandEvalMetrics& m, const std::string& command,
                              const std::vector<HandSceneOutcome>& scenes) {
  std::ostringstream j;
  j << "{\n";
  j << "  \"command\": \"" << esc(command) << "\",\n";
  j << "  \"scenes\": " << m.scenes << ",\n";
  j << "  \"failed_scenes\": " << m.failed_scenes << ",\n";
  j << "  \"stripe_runs\": " << m.stripe_runs << ",\n";
  j << "  \"stripe_converged\": " << m.stripe_converged << ",\n";
  j << "  \"stripe_within_tolerance_rate\": " << rate(m.stripe_within, m.stripe_runs) << ",\n";
  j << "  \"stripe_error_mm\": {\"x\": " << stats_json(m.stripe_abs_mm[0])
    << ", \"y\": " << stats_json(m.stripe_abs_mm[1]) << "},\n";
  j << "  \"corner_runs\": " << m.corner_runs << ",\n";
  j << "  \"corner_converged\": " << m.corner_converged << ",\n";
  j << "  \"p2_within_grasp_tolerance_rate\": " << rate(m.corner_within, m.corner_runs) << ",\n";
  j << "  \"p2_error_mm\": {\"x\": " << stats_json(m.p2_abs_mm[0]) << ", \"y\": " << stats_json(m.p2_abs_mm[1])
    << ", \"z\": " << stats_json(m.p2_abs_mm[2]) << "},\n";
  j << "  \"slope_error_deg\": " << stats_json(m.slope_abs_deg) << ",\n";
  j << "  \"slope_within_3deg_rate\": " << rate(m.slope_within, m.corner_converged) << ",\n";
  j << "  \"servo_iterations\": " << stats_json(m.iterations) << ",\n";
  j << "  \"servo_iterations_stripe\": " << stats_json(m.stripe_iterations) << ",\n";
  j << "  \"servo_iterations_corner\": " << stats_json(m.corner_iterations) << ",\n";
  j << "  \"time_to_converge_s\": {\"stripe\": " << stats_json(m.stripe_time_s)
    << ", \"corner\": " << stats_json(m.corner_time_s) << "},\n";
  j << "  \"ms_per_frame\": {\"bwh\": " << stats_json(m.bwh_ms) << ", \"bswh\": " << stats_json(m.bswh_ms)
    << ", \"markers\": " << stats_json(m.markers_ms) << "},\n";
  j << "  \"scene_wall_s\": " << stats_json(m.scene_wall_s) << ",\n";
  j << "  \"failures\": [";
  bool first = true;
  for (const auto& f : m.failures) {
    j << (first ? "\n" : ",\n") << "    {\"seed\": " << f.seed << ", \"task\": \"" << esc(f.task)
      << "\", \"reason\": \"" << esc(f.reason) << "\"}";
    first = false;
  }
  j << (m.failures.empty() ? "]" : "\n  ]");
  if (!scenes.empty()) {
    j << ",\n  \"runs\": [";
    for (size_t i = 0; i < scenes.size(); ++i) {
      const HandSceneOutcome& o = scenes[i];
      j << (i ? ",\n" : "\n") << "    {\"seed\": " << o.seed << ", \"wall_s\": " << num(o.wall_s)
        << ", \"corner_offset_mm\": [" << num(o.corner_offset_x_m * 1e3) << ", " << num(o.corner_offset_y_m * 1e3)
        << "],\n     \"stripe\": " << task_json(o.stripe) << ",\n     \"corner\": " << task_json(o.corner) << "}";
    }
    j << "\n  ]";
  }
  j << "\n}\n";
  return j.str();
}

namespace {

const cv::Scalar kBlack(0, 0, 0), kRed(40, 40, 210), kBlue(200, 100, 30), kGrey(150, 150, 150);

std::string fmt(const char* f, double v) {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

void text(cv::Mat& img, const std::string& s, cv::Point p, double scale = 0.45, cv::Scalar c = kBlack) {
  cv::putText(img, s, p, cv::FONT_HERSHEY_SIMPLEX, scale, c, 1, cv::LINE_AA);
}

/// A plot frame: data range [x0, x1] x [y0, y1] into a W x H image with margins.
struct Frame {
  int W = 640, H = 360, L = 60, R = 20, T = 40, B = 45;
  double x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  cv::Point px(double x, double y) const {
    return {static_cast<int>(std::lround(L + (x - x0) / (x1 - x0) * (W - L - R))),
            static_cast<int>(std::lround(H - B - (y - y0) / (y1 - y0) * (H - T - B)))};
  }
};

/// Axes with ticks at 5 steps and labels.
cv::Mat axes(const Frame& f, const std::string& title, const std::string& xlabel, const std::string& ylabel) {
  cv::Mat img(f.H, f.W, CV_8UC3, cv::Scalar(255, 255, 255));
  cv::rectangle(img, f.px(f.x0, f.y0), f.px(f.x1, f.y1), kBlack, 1);
  for (int i = 0; i <= 4; ++i) {
    const double x = f.x0 + (f.x1 - f.x0) * i / 4.0, y = f.y0 + (f.y1 - f.y0) * i / 4.0;
    const cv::Point px = f.px(x, f.y0), py = f.px(f.x0, y);
    cv::line(img, px, px + cv::Point(0, 4), kBlack);
    text(img, fmt("%.3g", x), px + cv::Point(-10, 18), 0.4);
    cv::line(img, py, py - cv::Point(4, 0), kBlack);
    text(img, fmt("%.3g", y), py + cv::Point(-45, 4), 0.4);
    if (y != f.y0 && y != f.y1) cv::line(img, f.px(f.x0, y), f.px(f.x1, y), cv::Scalar(230, 230, 230), 1);
  }
  text(img, title, cv::Point(f.L, 24), 0.55);
  text(img, xlabel, cv::Point(f.W / 2 - 60, f.H - 8));
  text(img, ylabel, cv::Point(4, f.T - 8), 0.4);
  return img;
}

/// A +-tol band around 0 (filled, light colour).
void band(cv::Mat& img, const Frame& f, double tol, cv::Scalar colour) {
  cv::Mat over = img.clone();
  cv::rectangle(over, f.px(f.x0, -tol), f.px(f.x1, tol), colour, cv::FILLED);
  cv::addWeighted(over, 0.35, img, 0.65, 0, img);
}

double range_of(const std::vector<double>& a, const std::vector<double>& b, double at_least) {
  double r = at_least;
  for (double v : a) r = std::max(r, std::abs(v));
  for (double v : b) r = std::max(r, std::abs(v));
  return std::ceil(r * 1.1 / 5.0) * 5.0;
}

/// Per-scene signed errors of two series (X red, Y blue) with their tolerance bands, like Figure 13.
cv::Mat per_scene(const std::string& title, const std::vector<double>& xs, const std::vector<double>& ys, double tol_x,
                  double tol_y, const std::string& ylabel) {
  Frame f;
  f.W = 900;
  f.x0 = 0;
  f.x1 = std::max<double>(2, static_cast<double>(std::max(xs.size(), ys.size())) + 1);
  const double r = range_of(xs, ys, std::max(tol_x, tol_y) * 1.3);
  f.y0 = -r;
  f.y1 = r;
  cv::Mat img = axes(f, title, "run (scene in seed order)", ylabel);
  band(img, f, tol_x, cv::Scalar(120, 220, 120));  // green: X tolerance
  band(img, f, tol_y, cv::Scalar(80, 220, 240));   // yellow: Y tolerance
  cv::line(img, f.px(f.x0, 0), f.px(f.x1, 0), kGrey, 1);
  const bool lines = xs.size() <= 60;
  auto series = [&](const std::vector<double>& v, cv::Scalar c, int dx) {
    for (size_t i = 0; i < v.size(); ++i) {
      const cv::Point p = f.px(static_cast<double>(i + 1), v[i]) + cv::Point(dx, 0);
      cv::circle(img, p, 3, c, cv::FILLED, cv::LINE_AA);
      if (lines && i > 0)
        cv::line(img, f.px(static_cast<double>(i), v[i - 1]) + cv::Point(dx, 0), p, c, 1, cv::LINE_AA);
    }
  };
  series(xs, kRed, -1);
  series(ys, kBlue, 1);
  if (ys.empty()) {
    text(img, "band: +-" + fmt("%.0f", tol_x), cv::Point(f.W - 250, f.H - 8), 0.4);
  } else {
    text(img, "X (up)", cv::Point(f.W - 250, 24), 0.45, kRed);
    text(img, "Y (right)", cv::Point(f.W - 180, 24), 0.45, kBlue);
    text(img, "bands: +-" + fmt("%.0f", tol_x) + " (X), +-" + fmt("%.0f", tol_y) + " (Y)",
         cv::Point(f.W - 250, f.H - 8), 0.4);
  }
  return img;
}

/// Scatter of (Y, X) errors with the tolerance box.
cv::Mat scatter(const std::string& title, const std::vector<double>& xs, const std::vector<double>& ys, double tol_x,
                double tol_y) {
  Frame f;
  f.W = 480;
  f.H = 480;
  const double r = range_of(xs, ys, std::max(tol_x, tol_y) * 1.3);
  f.x0 = -r;
  f.x1 = r;
  f.y0 = -r;
  f.y1 = r;
  cv::Mat img = axes(f, title, "Y error (right), mm", "X error (up), mm");
  cv::Mat over = img.clone();
  cv::rectangle(over, f.px(-tol_y, -tol_x), f.px(tol_y, tol_x), cv::Scalar(120, 220, 120), cv::FILLED);
  cv::addWeighted(over, 0.35, img, 0.65, 0, img);
  cv::line(img, f.px(f.x0, 0), f.px(f.x1, 0), kGrey, 1);
  cv::line(img, f.px(0, f.y0), f.px(0, f.y1), kGrey, 1);
  for (size_t i = 0; i < xs.size() && i < ys.size(); ++i)
    cv::drawMarker(img, f.px(ys[i], xs[i]), kBlue, cv::MARKER_CROSS, 7, 1, cv::LINE_AA);
  text(img,
       "n = " + std::to_string(xs.size()) + ", box: +-" + fmt("%.0f", tol_y) + " mm Y, +-" + fmt("%.0f", tol_x) +
           " mm X",
       cv::Point(f.L + 4, f.T + 16), 0.4);
  return img;
}

cv::Mat stack(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat out(a.rows + b.rows, std::max(a.cols, b.cols), CV_8UC3, cv::Scalar(255, 255, 255));
  a.copyTo(out(cv::Rect(0, 0, a.cols, a.rows)));
  b.copyTo(out(cv::Rect(0, a.rows, b.cols, b.rows)));
  return out;
}

cv::Mat side_by_side(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat out(std::max(a.rows, b.rows), a.cols + b.cols, CV_8UC3, cv::Scalar(255, 255, 255));
  a.copyTo(out(cv::Rect(0, 0, a.cols, a.rows)));
  b.copyTo(out(cv::Rect(a.cols, 0, b.cols, b.rows)));
  return out;
}

void write_png(const std::string& path, const cv::Mat& img) {
  if (!cv::imwrite(path, img)) throw std::runtime_error("cannot write " + path);
}

std::string stat_line(const std::vector<double>& v, const char* unit) {
  const HandStats s = hand_stats(v);
  char b[200];
  std::snprintf(b, sizeof b, "mean %.2f, median %.2f, p95 %.2f, max %.2f %s (n = %d)", s.mean, s.median, s.p95, s.max,
                unit, s.n);
  return b;
}

std::string pct(int k, int n) {
  if (n <= 0) return "n/a";
  char b[64];
  std::snprintf(b, sizeof b, "%d of %d (%.1f %%)", k, n, 100.0 * k / n);
  return b;
}

}  // namespace

cv::Mat stripe_end_figure(const std::vector<double>& x_mm, const std::vector<double>& y_mm, double tol_x_mm,
                          double tol_y_mm) {
  return side_by_side(scatter("Figure 14: stripe end error (PS - true end)", x_mm, y_mm, tol_x_mm, tol_y_mm),
                      per_scene("stripe end error per run", x_mm, y_mm, tol_x_mm, tol_y_mm, "mm"));
}

void write_hand_report(const std::string& dir, const HandEvalMetrics& m, const std::vector<HandSceneOutcome>& scenes,
                       const HandTolerances& tol, const std::string& command) {
  std::vector<double> sx, sy, px, py, pz, slope;
  for (const HandSceneOutcome& o : scenes) {
    if (o.stripe.run && o.stripe.converged) {
      sx.push_back(o.stripe.error_x_m * 1e3);
      sy.push_back(o.stripe.error_y_m * 1e3);
    }
    if (o.corner.run && o.corner.converged) {
      px.push_back(o.corner.error_x_m * 1e3);
      py.push_back(o.corner.error_y_m * 1e3);
      pz.push_back(o.corner.error_z_m * 1e3);
      slope.push_back(o.corner.slope_error_deg);
    }
  }
  const cv::Mat fig13 = stack(
      per_scene("Figure 13: P2 - P1 (BwH servo vs true P1) per run", px, py, tol.p2_x_m * 1e3, tol.p2_y_m * 1e3, "mm"),
      per_scene("P2 depth error (Z - standoff) per run", pz, {}, 5.0, 5.0, "mm"));
  write_png(dir + "/figure13_p2_error.png", fig13);
  write_png(dir + "/figure14_stripe_end.png", stripe_end_figure(sx, sy, tol.stripe_x_m * 1e3, tol.stripe_y_m * 1e3));
  write_png(dir + "/slope_error.png", per_scene("book slope error (gripper roll - true lean) per run", slope, {},
                                                tol.slope_deg, tol.slope_deg, "deg"));

  std::ofstream r(dir + "/report.md");
  if (!r) throw std::runtime_error("cannot write " + dir + "/report.md");
  r << "# Hand-camera evaluation (visual servoing closed in simulation)\n\n";
  r << "Command: `" << command << "`\n\n";
  r << "Errors against SIM_GROUND_TRUTH, in the cart's grasp frame (X up, Y right, Z into the shelf).\n\n";
  r << "| what | result | paper |\n|---|---|---|\n";
  r << "| scenes | " << m.scenes << " (" << m.failed_scenes << " with a failure) | 20 runs |\n";
  r << "| stripe servo converged | " << pct(m.stripe_converged, m.stripe_runs) << " | |\n";
  r << "| stripe end within 1.5 cm X / 1 cm Y | " << pct(m.stripe_within, m.stripe_runs) << " | always |\n";
  r << "| stripe end error X (up) | " << stat_line(m.stripe_abs_mm[0], "mm") << " | |\n";
  r << "| stripe end error Y (right) | " << stat_line(m.stripe_abs_mm[1], "mm") << " | |\n";
  r << "| corner servo converged | " << pct(m.corner_converged, m.corner_runs) << " | |\n";
  r << "| P2 within 2 cm X / 1.5 cm Y of P1 | " << pct(m.corner_within, m.corner_runs) << " | 80 % (vs BwS P1) |\n";
  r << "| P2 error X | " << stat_line(m.p2_abs_mm[0], "mm") << " | |\n";
  r << "| P2 error Y | " << stat_line(m.p2_abs_mm[1], "mm") << " | |\n";
  r << "| P2 error Z (standoff kept) | " << stat_line(m.p2_abs_mm[2], "mm") << " | |\n";
  r << "| slope error | " << stat_line(m.slope_abs_deg, "deg")
    << "; within 3 deg: " << pct(m.slope_within, m.corner_converged) << " | always within 3 deg |\n";
  r << "| servo iterations (both tasks) | " << stat_line(m.iterations, "") << " | |\n";
  r << "| stripe servo time | " << stat_line(m.stripe_time_s, "s") << " | |\n";
  r << "| corner servo time | " << stat_line(m.corner_time_s, "s") << " | |\n";
  r << "| BwH per frame | " << stat_line(m.bwh_ms, "ms") << " | |\n";
  r << "| BSwH per frame | " << stat_line(m.bswh_ms, "ms") << " | |\n";
  r << "| markers per frame | " << stat_line(m.markers_ms, "ms") << " | |\n";
  r << "| wall time per scene | " << stat_line(m.scene_wall_s, "s") << " | |\n\n";
  r << "![Figure 13](figure13_p2_error.png)\n\n![Figure 14](figure14_stripe_end.png)\n\n![slope](slope_error.png)\n\n";
  r << "## Failures\n\n";
  if (m.failures.empty()) r << "None.\n";
  for (const auto& f : m.failures) r << "- seed " << f.seed << " (" << f.task << "): " << f.reason << "\n";
}

}  // namespace bookgrasp
