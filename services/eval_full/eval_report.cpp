#include "services/eval_full/eval_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "services/eval_hand/hand_eval_metrics.h"

namespace bookgrasp {

namespace {

std::string f2(double v, const char* f = "%.2f") {
  char b[64];
  std::snprintf(b, sizeof b, f, v);
  return b;
}

std::string pct(int k, int n) { return n > 0 ? f2(100.0 * k / n, "%.1f") + " % (" + std::to_string(k) + "/" + std::to_string(n) + ")" : "n/a"; }

/// A histogram of `v` with `bins` bins over [lo, hi], a dashed line at each of `marks`. White background, BGR.
cv::Mat histogram(const std::vector<double>& v, double lo, double hi, int bins, const std::string& title,
                  const std::string& xlabel, const std::vector<double>& marks) {
  const int W = 640, H = 400, L = 60, R = 20, T = 40, B = 60;
  cv::Mat img(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
  std::vector<int> count(bins, 0);
  long over = 0;  // values beyond hi, counted in the last bar
  for (double x : v) {
    over += x > hi;
    int k = static_cast<int>(std::floor((x - lo) / (hi - lo) * bins));
    k = std::clamp(k, 0, bins - 1);
    ++count[k];
  }
  const int cmax = std::max(1, *std::max_element(count.begin(), count.end()));
  const double bw = static_cast<double>(W - L - R) / bins;
  for (int k = 0; k < bins; ++k) {
    const int h = static_cast<int>((H - T - B) * count[k] / static_cast<double>(cmax));
    cv::rectangle(img, cv::Point(static_cast<int>(L + k * bw) + 1, H - B - h),
                  cv::Point(static_cast<int>(L + (k + 1) * bw) - 1, H - B), cv::Scalar(180, 120, 40), cv::FILLED);
  }
  cv::line(img, cv::Point(L, H - B), cv::Point(W - R, H - B), cv::Scalar(0, 0, 0), 1);
  cv::line(img, cv::Point(L, T), cv::Point(L, H - B), cv::Scalar(0, 0, 0), 1);
  for (double m : marks) {
    const int x = static_cast<int>(L + (m - lo) / (hi - lo) * (W - L - R));
    for (int y = T; y < H - B; y += 8) cv::line(img, cv::Point(x, y), cv::Point(x, y + 4), cv::Scalar(0, 0, 200), 1);
  }
  for (int i = 0; i <= 4; ++i) {
    const double x = lo + (hi - lo) * i / 4;
    const int px = static_cast<int>(L + (W - L - R) * i / 4.0);
    // Centred on its tick, but inside the image (the last one was cut at the right edge: "2e+0").
    const std::string label = f2(x, "%.3g");
    const int width = cv::getTextSize(label, cv::FONT_HERSHEY_SIMPLEX, 0.4, 1, nullptr).width;
    cv::putText(img, label, cv::Point(std::clamp(px - width / 2, 2, W - width - 2), H - B + 18), cv::FONT_HERSHEY_SIMPLEX,
                0.4, cv::Scalar(0, 0, 0));
  }
  cv::putText(img, std::to_string(cmax), cv::Point(8, T + 10), cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 0));
  cv::putText(img, title + "  (n = " + std::to_string(v.size()) + ")", cv::Point(L, 25), cv::FONT_HERSHEY_SIMPLEX, 0.55,
              cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  if (over > 0)  // values beyond hi are counted in the last bar: say how many
    cv::putText(img, std::to_string(over) + " over " + f2(hi, "%.3g") + ", in the last bar", cv::Point(W - R - 150, T - 3),
                cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 0, 200), 1, cv::LINE_AA);
  cv::putText(img, xlabel, cv::Point(L + 150, H - 15), cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(0, 0, 0), 1,
              cv::LINE_AA);
  return img;
}

/// Bars of rates with the paper's value beside ours (paper Section 5 figures as bars).
cv::Mat rates_plot(const std::vector<std::string>& names, const std::vector<double>& ours,
                   const std::vector<double>& paper) {
  const int W = 640, H = 400, L = 60, B = 80, T = 40;
  cv::Mat img(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
  const int n = static_cast<int>(names.size());
  const double slot = static_cast<double>(W - L - 20) / n;
  for (int i = 0; i < n; ++i) {
    const auto bar = [&](double v, int off, cv::Scalar c) {
      if (!std::isfinite(v)) return;
      const int h = static_cast<int>((H - T - B) * std::clamp(v, 0.0, 1.0));
      const int x0 = static_cast<int>(L + i * slot + off);
      cv::rectangle(img, cv::Point(x0, H - B - h), cv::Point(x0 + static_cast<int>(slot / 3), H - B), c, cv::FILLED);
      cv::putText(img, f2(100 * v, "%.0f%%"), cv::Point(x0, H - B - h - 4), cv::FONT_HERSHEY_SIMPLEX, 0.4,
                  cv::Scalar(0, 0, 0));
    };
    bar(ours[i], static_cast<int>(slot / 8), cv::Scalar(180, 120, 40));
    bar(paper[i], static_cast<int>(slot / 8 + slot / 3 + 4), cv::Scalar(160, 160, 160));
    cv::putText(img, names[i], cv::Point(static_cast<int>(L + i * slot + 4), H - B + 20), cv::FONT_HERSHEY_SIMPLEX,
                0.4, cv::Scalar(0, 0, 0));
  }
  cv::line(img, cv::Point(L, H - B), cv::Point(W - 20, H - B), cv::Scalar(0, 0, 0), 1);
  cv::putText(img, "rates: this system (blue) vs the paper (grey)", cv::Point(L, 25), cv::FONT_HERSHEY_SIMPLEX, 0.55,
              cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  return img;
}

double rate(int k, int n) { return n > 0 ? static_cast<double>(k) / n : NAN; }

}  // namespace

void write_report(const std::string& dir, const EvalMetrics& m, const std::string& command, int books_per_scene) {
  const MetricTolerances tol;  // the ones eval_full measures with
  // Plots (PNG, OpenCV).
  cv::imwrite(dir + "/rates.png",
              rates_plot({"grasp", "P1-P2 agree", "width<1cm", "books moved", "upright"},
                         {rate(m.grasp_successes, m.grasp_attempts), rate(m.decisions_agreeing, m.decisions),
                          rate(m.widths_within, m.widths), rate(m.books_moved, m.books_targeted),
                          rate(m.books_upright_on_lower_shelf, m.books_upright_checked)},
                         {0.75, 0.80, 0.65, NAN, NAN}));
  cv::imwrite(dir + "/width_error.png",
              histogram(m.width_error_mm, 0, 20, 20, "book width error |BW - true| (paper Fig. 15)", "mm", {10}));
  std::vector<double> dy = m.p1_p2_dy_mm;
  cv::imwrite(dir + "/p1_p2_y.png",
              histogram(dy, -30, 30, 30, "P2.y - P1.y in the grasp frame (paper Sec. 5.2)", "mm", {-15, 15}));
  const char* ax[3] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k)
    cv::imwrite(dir + "/p1_error_" + ax[k] + ".png",
                histogram(m.p1_error_mm[k], 0, 30, 30, std::string("P1 error |") + ax[k] + "| vs truth (paper Fig. 12)",
                          "mm", {}));
  cv::imwrite(dir + "/figure14_stripe_end.png", stripe_end_figure(m.stripe_error_mm[0], m.stripe_error_mm[1],
                                                                  tol.stripe_x_m * 1e3, tol.stripe_y_m * 1e3));
  cv::imwrite(dir + "/cycle_time.png", histogram(m.cycle_s, 0, 300, 30, "cycle time per moved book", "s", {}));
  cv::imwrite(dir + "/planning_time.png", histogram(m.plan_ms, 0, 2000, 40, "planning time per request", "ms", {2000}));

  const Stats w = stats_of(m.width_error_mm), c = stats_of(m.cycle_s), p = stats_of(m.plan_ms),
              sw = stats_of(m.scene_wall_s);
  std::ofstream md(dir + "/report.md");
  md << "# Full-cycle evaluation\n\n";
  md << "Command: `" << command << "`\n\n";
  md << "Scenes: " << m.scenes << "; books per scene: " << (books_per_scene > 0 ? std::to_string(books_per_scene) : "all")
     << "; wall time per scene: median " << f2(sw.median, "%.0f") << " s, max " << f2(sw.max, "%.0f") << " s.\n\n";
  md << "| figure | this system | paper (Sec. 5) |\n|---|---|---|\n";
  md << "| grasp success | " << pct(m.grasp_successes, m.grasp_attempts) << " | 75 % (15/20) |\n";
  md << "| other books a grasp took out with the target (counted as failed grasps) | " << m.books_carried_along
     << " | - |\n";
  md << "| books no grasp targeted that left the upper shelf | " << m.untargeted_books_off_the_upper_shelf
     << " | - |\n";
  md << "| books through the whole cycle | " << pct(m.books_moved, m.books_targeted) << " | - |\n";
  md << "| ... of them standing upright on the lower shelf at the end (scenes that checked) | "
     << pct(m.books_upright_on_lower_shelf, m.books_upright_checked) << " | - |\n";
  md << "| books left on the holder for the librarian: too tall for the lower shelf / not placeable there | "
     << m.books_handed_over - m.books_handed_over_unplaceable << " / " << m.books_handed_over_unplaceable << " | - |\n";
  md << "| right-most books that did not stand (fallen, or leaning on the side panel), passed over for the right-most "
        "standing book | "
     << m.books_passed_over_not_standing << " | - |\n";
  md << "| P1-P2 agreement (|dY| <= 15 mm, |dX| <= 20 mm) | " << pct(m.decisions_agreeing, m.decisions) << " | 80 % |\n";
  md << "| ... disagreeing: P1 off in Y (another book) / above the corner (X, on a taller neighbour) / below it / P2 "
        "off "
        "(P1 near the corner) | "
     << m.p1_p2_disagreements[0] << " / " << m.p1_p2_disagreements[1] << " / " << m.p1_p2_disagreements[2] << " / "
     << m.p1_p2_disagreements[3] << " | - |\n";
  md << "| book width within 1 cm | " << pct(m.widths_within, m.widths) << " | 65 % |\n";
  {
    const Stats sx = stats_of(m.stripe_error_mm[0]), sy = stats_of(m.stripe_error_mm[1]);
    md << "| stripe end PS within " << f2(tol.stripe_x_m * 1e3, "%.0f") << " mm X and "
       << f2(tol.stripe_y_m * 1e3, "%.0f") << " mm Y of the truth | " << pct(m.stripes_within, m.stripes)
       << " | every time (Fig. 14) |\n";
    md << "| stripe end error X / Y mean, min / max | " << f2(sx.mean, "%.1f") << " (" << f2(sx.min, "%.1f") << " / "
       << f2(sx.max, "%.1f") << ") / " << f2(sy.mean, "%.1f") << " (" << f2(sy.min, "%.1f") << " / "
       << f2(sy.max, "%.1f") << ") mm | - |\n";
  }
  md << "| book width error mean / max | " << f2(w.mean, "%.1f") << " / " << f2(w.max, "%.1f") << " mm | - |\n";
  for (int k = 0; k < 3; ++k) {
    const Stats e = stats_of(m.p1_error_mm[k]);
    md << "| P1 error " << "XYZ"[k] << " mean (n) | " << f2(e.mean, "%.1f") << " mm (" << e.n << ") | "
       << (k == 0 ? "5.2" : k == 1 ? "11.7" : "3.8") << " mm |\n";
  }
  for (int k = 0; k < 3; ++k) {
    const Stats e = stats_of(m.gp_error_mm[k]);
    md << "| GP - true corner "
       << "XYZ"[k] << " mean / min / max (n) | " << f2(e.mean, "%.1f") << " / " << f2(e.min, "%.1f") << " / "
       << f2(e.max, "%.1f") << " mm (" << e.n << ") | - |\n";
  }
  for (int k = 0; k < 3; ++k) {
    const Stats e = stats_of(m.gp_base_error_mm[k]);
    md << "| GP in base - true corner (true frame) "
       << "XYZ"[k] << " mean / min / max (n) | " << f2(e.mean, "%.1f") << " / " << f2(e.min, "%.1f") << " / "
       << f2(e.max, "%.1f") << " mm (" << e.n << ") | - |\n";
  }
  for (int k = 0; k < 4; ++k) {
    const Stats e = stats_of(m.plates_over_fore_edge_mm[k]);
    md << "| plates - fore-edge at the close, " << kCloseOutcomes[k] << " min / median / max (n) | "
       << f2(e.min, "%.1f") << " / " << f2(e.median, "%.1f") << " / " << f2(e.max, "%.1f") << " mm (" << e.n
       << ") | - |\n";
  }
  md << "| cycle time per book median / p95 | " << f2(c.median, "%.0f") << " / " << f2(c.p95, "%.0f") << " s | - |\n";
  md << "| planning time mean / max | " << f2(p.mean, "%.0f") << " / " << f2(p.max, "%.0f") << " ms | < 2 s |\n\n";
  md << "![rates](rates.png)\n![width error](width_error.png)\n![P1-P2](p1_p2_y.png)\n"
        "![P1 x](p1_error_x.png)\n![P1 y](p1_error_y.png)\n![P1 z](p1_error_z.png)\n"
        "![stripe end](figure14_stripe_end.png)\n![cycle](cycle_time.png)\n![planning](planning_time.png)\n\n";
  md << "## Failure modes\n\n";
  if (m.failure_modes.empty()) md << "None.\n";
  for (const auto& [why, n] : m.failure_modes) md << "- " << n << " x " << why << "\n";
  md << "\n## Short of the aims, by seed (scenes; re-run one alone with `--scenes 1 --seed <seed>`)\n\n";
  if (m.shortfall_seeds.empty()) md << "None.\n";
  for (const auto& [kind, seeds] : m.shortfall_seeds) {
    md << "- " << kind << " (" << seeds.size() << "):";
    for (uint64_t s : seeds) md << " " << s;
    md << "\n";
  }
  md << "\n## Failures (re-run one alone with `--scenes 1 --seed <seed>`)\n\n";
  if (m.failures.empty()) md << "None.\n";
  for (const auto& [seed, why] : m.failures) md << "- seed " << seed << ": " << why << "\n";
}

}  // namespace bookgrasp
