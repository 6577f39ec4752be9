#include "services/eval_segmentation/segmentation_eval.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "common/config.h"
#include "services/bws_detector/disparity.h"

namespace bookgrasp::eval_segmentation {

EvalConfig EvalConfig::from_files(const std::string& god_config, const std::string& pcl_config) {
  EvalConfig c;
  c.god = bws::BwsParams::from_config(Config::load_file(god_config));
  c.pcl = bws::BwsParams::from_config(Config::load_file(pcl_config));
  if (c.god.implementation != bws::kImplGod)
    throw std::invalid_argument(god_config + " is for implementation '" + c.god.implementation + "', not god");
  if (c.pcl.implementation != bws::kImplPcl)
    throw std::invalid_argument(pcl_config + " is for implementation '" + c.pcl.implementation + "', not pcl");
  return c;
}

const char* gt_category_name(int c) {
  switch (c) {
    case kBookFront:
      return "book_front";
    case kBookOther:
      return "book_other";
    case kCurved:
      return "curved";
    case kOtherPlanar:
      return "other_planar";
    default:
      return "?";
  }
}

int gt_category_of(const GtRegion& r) {
  if (!r.planar) return kCurved;
  if (r.owner >= 0) return r.name.find("_pages:+z") != std::string::npos ? kBookFront : kBookOther;
  return kOtherPlanar;
}

double effective_tolerance(double nominal) {
  return nominal <= 0.5 ? 0.5 + 1e-6 : nominal;
}

std::string tolerance_key(double nominal) {
  char b[32];
  std::snprintf(b, sizeof b, "T%g", nominal);
  return b;
}

cv::Mat true_disparity(const cv::Mat& depth, double fx, double baseline_m, double noise_px, double quantum_px,
                       uint64_t seed) {
  if (depth.type() != CV_32F) throw std::invalid_argument("true_disparity: depth must be CV_32F");
  if (!(fx > 0) || !(baseline_m > 0) || !(noise_px >= 0) || !(quantum_px >= 0))
    throw std::invalid_argument("true_disparity: fx and baseline must be > 0, noise and quantum >= 0");
  cv::RNG rng(seed ? seed : 1);
  cv::Mat d(depth.size(), CV_32F);
  for (int y = 0; y < depth.rows; ++y) {
    const float* z = depth.ptr<float>(y);
    float* o = d.ptr<float>(y);
    for (int x = 0; x < depth.cols; ++x) {
      const double n = rng.gaussian(1.0);  // drawn for every pixel: the noise pattern does not depend on the depth
      if (!std::isfinite(z[x]) || z[x] <= 0) {
        o[x] = std::numeric_limits<float>::quiet_NaN();
        continue;
      }
      double v = fx * baseline_m / z[x] + noise_px * n;
      if (quantum_px > 0) v = std::round(v / quantum_px) * quantum_px;
      o[x] = v > 0 ? float(v) : std::numeric_limits<float>::quiet_NaN();
    }
  }
  return d;
}

namespace {

using Clock = std::chrono::steady_clock;

void run_methods(const std::string& suffix, const cv::Mat& disparity, const bws::StereoGeometry& g, const cv::Mat& gt,
                 const EvalConfig& c, std::vector<MethodRun>* runs) {
  const cv::Mat points = bws::disparity_to_points(disparity, g);
  const auto run = [&](const std::string& name, auto&& fn) {
    MethodRun r;
    r.name = name + suffix;
    const auto t0 = Clock::now();
    r.labels = fn().labels;
    r.ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    for (double T : c.tolerances) r.hoover.push_back(hoover_compare(gt, r.labels, effective_tolerance(T)));
    runs->push_back(std::move(r));
  };
  run("god", [&] { return bws::segment(disparity, points, c.god); });
  if (c.steep_curvature > 0) {
    bws::BwsParams steep = c.god;
    steep.god.jump_min_curvature = c.steep_curvature;
    run("god_steep", [&] { return bws::segment(disparity, points, steep); });
  }
  run("pcl", [&] { return bws::segment(disparity, points, c.pcl); });
  run("jump", [&] { return bws::segment_jump_components(disparity, points, c.jump); });
  run("rg", [&] {
    bws::SegmentationResult r;
    r.labels = segment_region_growing(points, c.region_growing);
    return r;
  });
}

std::string pct(double f) {
  char b[32];
  std::snprintf(b, sizeof b, "%.1f", 100.0 * f);
  return b;
}
std::string fx3(double f) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4f", f);
  return b;
}

}  // namespace

SceneEval evaluate_scene(const RangeScene& s, uint64_t seed, const EvalConfig& c) {
  SceneEval e;
  e.seed = seed;
  e.gt_regions = int(s.regions.size());
  for (const GtRegion& r : s.regions) e.curved_gt_regions += r.planar ? 0 : 1;
  e.curved_objects_placed = s.curved_objects_placed;
  e.rightmost_front_label = s.rightmost_front_label();
  for (const GtRegion& r : s.regions) e.gt_category.push_back(gt_category_of(r));
  bws::StereoGeometry g;
  g.fx = s.left_camera.fx;
  g.fy = s.left_camera.fy;
  g.cx = s.left_camera.cx;
  g.cy = s.left_camera.cy;
  g.baseline_m = s.baseline_m;
  e.disparity_true = true_disparity(s.depth, g.fx, g.baseline_m, c.true_noise_px, c.disparity_quantum_px, seed);
  run_methods("", e.disparity_true, g, s.gt_labels, c, &e.runs);
  if (c.stereo) {
    e.disparity_stereo = bws::compute_disparity(s.left_rgb, s.right_rgb, c.god.disparity);
    long long labelled = 0, valid = 0;
    std::vector<float> err;
    for (int y = 0; y < s.gt_labels.rows; ++y)
      for (int x = 0; x < s.gt_labels.cols; ++x)
        if (s.gt_labels.at<int>(y, x) > 0) {
          ++labelled;
          const float v = e.disparity_stereo.at<float>(y, x);
          if (!(std::isfinite(v) && v > 0)) continue;
          ++valid;
          const float z = s.depth.at<float>(y, x);
          err.push_back(std::fabs(v - float(g.fx * g.baseline_m / z)));
        }
    e.stereo_coverage = labelled ? double(valid) / double(labelled) : 0.0;
    if (err.empty()) {
      e.stereo_median_error_px = std::numeric_limits<double>::quiet_NaN();
    } else {
      std::nth_element(err.begin(), err.begin() + long(err.size() / 2), err.end());
      e.stereo_median_error_px = err[err.size() / 2];
    }
    run_methods("_stereo", e.disparity_stereo, g, s.gt_labels, c, &e.runs);
  }
  return e;
}

std::vector<MethodSummary> summarize(const std::vector<SceneEval>& scenes, const EvalConfig& c) {
  std::vector<MethodSummary> out;
  if (scenes.empty()) return out;
  size_t t08 = c.tolerances.size();
  for (size_t i = 0; i < c.tolerances.size(); ++i)
    if (std::fabs(c.tolerances[i] - 0.8) < 1e-9) t08 = i;
  for (size_t k = 0; k < scenes.front().runs.size(); ++k) {
    MethodSummary m;
    m.name = scenes.front().runs[k].name;
    m.totals.resize(c.tolerances.size());
    std::vector<double> ms;
    for (const SceneEval& s : scenes) {
      const MethodRun& r = s.runs.at(k);
      for (size_t i = 0; i < r.hoover.size(); ++i) m.totals[i].add(r.hoover[i]);
      ms.push_back(r.ms);
      if (s.rightmost_front_label > 0 && t08 < r.hoover.size()) {
        ++m.rightmost_front_scenes;
        m.rightmost_front_correct += r.hoover[t08].gt_class_of(s.rightmost_front_label) == HooverClass::kCorrect;
      }
      if (t08 < r.hoover.size())
        for (size_t i = 0; i < s.gt_category.size(); ++i) {
          ++m.category_regions[size_t(s.gt_category[i])];
          m.category_correct[size_t(s.gt_category[i])] +=
              r.hoover[t08].gt_class_of(int(i) + 1) == HooverClass::kCorrect;
        }
    }
    std::sort(ms.begin(), ms.end());
    m.median_ms = ms.size() % 2 ? ms[ms.size() / 2] : 0.5 * (ms[ms.size() / 2 - 1] + ms[ms.size() / 2]);
    out.push_back(m);
  }
  return out;
}

std::string metrics_json(const std::vector<SceneEval>& scenes, const EvalConfig& c, const std::string& scene_file,
                         uint64_t first_seed, bool curved) {
  const std::vector<MethodSummary> ms = summarize(scenes, c);
  long long gt = 0, curved_gt = 0, placed = 0;
  double coverage = 0;
  std::vector<double> stereo_err;
  for (const SceneEval& s : scenes) {
    if (std::isfinite(s.stereo_median_error_px)) stereo_err.push_back(s.stereo_median_error_px);
    gt += s.gt_regions;
    curved_gt += s.curved_gt_regions;
    placed += s.curved_objects_placed;
    coverage += s.stereo_coverage;
  }
  std::sort(stereo_err.begin(), stereo_err.end());
  // FNV-1a 64 of the scene file's bytes: which version of a file that others edit the numbers come from.
  uint64_t h = 1469598103934665603ull;
  {
    std::ifstream f(scene_file, std::ios::binary);
    char ch;
    while (f.get(ch)) h = (h ^ uint64_t(uint8_t(ch))) * 1099511628211ull;
  }
  char hash[32];
  std::snprintf(hash, sizeof hash, "%016llx", (unsigned long long)h);
  std::ostringstream j;
  j << "{\n  \"scene_file\": \"" << scene_file << "\",\n  \"scene_file_fnv1a64\": \"" << hash
    << "\",\n  \"first_seed\": " << first_seed << ",\n  \"scenes\": " << scenes.size()
    << ",\n  \"curved_objects\": " << (curved ? "true" : "false") << ",\n  \"curved_objects_placed\": " << placed
    << ",\n  \"gt_regions\": " << gt << ",\n  \"curved_gt_regions\": " << curved_gt << ",\n"
    << "  \"fractions\": \"correct, over, under, missed: fractions of ground-truth regions (under counts the GT "
       "regions inside an under-segmentation; correct+over+under+missed = 1); noise: fraction of machine regions\",\n"
    << "  \"sources\": {\"true\": \"exact rendered depth as disparity + N(0, " << c.true_noise_px << " px), rounded to "
    << c.disparity_quantum_px
    << " px\", \"stereo\": \"bws_detector StereoBM disparity of the rendered pair (names *_stereo)\"},\n"
    << "  \"stereo_coverage\": " << fx3(scenes.empty() ? 0 : coverage / double(scenes.size())) << ",\n"
    << "  \"stereo_median_abs_error_px\": "
    << (stereo_err.empty() ? std::string("null") : fx3(stereo_err[stereo_err.size() / 2])) << ",\n"
    << "  \"stereo_note\": \"coverage: mean fraction of GT pixels with a stereo disparity; error: median over scenes "
       "of "
       "the per-scene median |stereo - exact| there\",\n"
    << "  \"tolerance_note\": \"T0.5 is evaluated at T = 0.500001 (Hoover: T > 0.5)\",\n"
    << "  \"paper_table1_T0.8_correct\": {\"GoD\": 0.73, \"EG\": 0.72, \"UE\": 0.68, \"UB\": 0.65, \"USF\": 0.60, "
       "\"WSU\": 0.40},\n  \"methods\": {\n";
  for (size_t k = 0; k < ms.size(); ++k) {
    const MethodSummary& m = ms[k];
    j << "    \"" << m.name << "\": {\n";
    for (size_t i = 0; i < c.tolerances.size(); ++i) {
      const HooverTotals& t = m.totals[i];
      j << "      \"" << tolerance_key(c.tolerances[i]) << "\": {\"correct\": " << fx3(t.correct_fraction())
        << ", \"over\": " << fx3(t.over_fraction()) << ", \"under\": " << fx3(t.under_fraction())
        << ", \"missed\": " << fx3(t.missed_fraction()) << ", \"noise\": " << fx3(t.noise_fraction())
        << ", \"counts\": {\"gt_regions\": " << t.gt_regions << ", \"machine_regions\": " << t.ms_regions
        << ", \"correct\": " << t.correct << ", \"over\": " << t.over << ", \"under\": " << t.under
        << ", \"under_gt_regions\": " << t.under_gt_regions << ", \"missed\": " << t.missed
        << ", \"noise\": " << t.noise << "}},\n";
    }
    j << "      \"correct_by_category_T0.8\": {";
    for (int g = 0; g < kNumCategories; ++g)
      j << (g ? ", " : "") << "\"" << gt_category_name(g) << "\": {\"gt_regions\": " << m.category_regions[size_t(g)]
        << ", \"correct\": " << m.category_correct[size_t(g)] << "}";
    j << "},\n";
    j << "      \"rightmost_front_correct_T0.8\": " << m.rightmost_front_correct
      << ",\n      \"rightmost_front_scenes\": " << m.rightmost_front_scenes
      << ",\n      \"ms_per_frame_median\": " << fx3(m.median_ms) << "\n    }" << (k + 1 < ms.size() ? "," : "")
      << "\n";
  }
  j << "  }\n}\n";
  return j.str();
}

std::string report_markdown(const std::vector<SceneEval>& scenes, const EvalConfig& c, const std::string& command,
                            bool curved) {
  const std::vector<MethodSummary> ms = summarize(scenes, c);
  long long gt = 0, curved_gt = 0;
  double coverage = 0;
  std::vector<double> stereo_err;
  for (const SceneEval& s : scenes) {
    gt += s.gt_regions;
    curved_gt += s.curved_gt_regions;
    coverage += s.stereo_coverage;
    if (std::isfinite(s.stereo_median_error_px)) stereo_err.push_back(s.stereo_median_error_px);
  }
  std::sort(stereo_err.begin(), stereo_err.end());
  std::ostringstream m;
  m << "# Segmentation evaluation (Hoover et al. 1996)\n\nCommand: `" << command << "`\n\n"
    << scenes.size() << " scenes, " << gt << " ground-truth regions (" << curved_gt << " curved), curved objects "
    << (curved ? "on" : "off") << ".\n"
    << "Sources: **true** = exact rendered depth as disparity + N(0, " << c.true_noise_px << " px), rounded to "
    << c.disparity_quantum_px << " px; **stereo** = bws_detector's block-matching disparity of the rendered pair";
  if (c.stereo && !scenes.empty())
    m << " (covers " << pct(coverage / double(scenes.size())) << " % of the GT pixels; median |error| there "
      << (stereo_err.empty() ? std::string("-") : fx3(stereo_err[stereo_err.size() / 2])) << " px)";
  m << ".\n\n"
    << "## Correct detection, % of ground-truth regions (paper's Table 1 layout; the paper has T = 0.8 only, "
       "on the Perceptron test set)\n\n| T |";
  for (const MethodSummary& s : ms) m << " " << s.name << " |";
  m << " paper GoD | EG | UE | UB | USF | WSU |\n|---|";
  for (size_t k = 0; k < ms.size() + 6; ++k) m << "---|";
  m << "\n";
  for (size_t i = 0; i < c.tolerances.size(); ++i) {
    m << "| " << c.tolerances[i] << " |";
    for (const MethodSummary& s : ms) m << " " << pct(s.totals[i].correct_fraction()) << " |";
    if (std::fabs(c.tolerances[i] - 0.8) < 1e-9)
      m << " 73 | 72 | 68 | 65 | 60 | 40 |\n";
    else
      m << " - | - | - | - | - | - |\n";
  }
  for (size_t i = 0; i < c.tolerances.size(); ++i) {
    m << "\n## All classes at T = " << c.tolerances[i]
      << "\n\n| method | correct % | over % | under % | missed % | noise % (of machine regions) | GT regions | "
         "machine regions | right-most front correct (T=0.8) | median ms "
         "|\n|---|---|---|---|---|---|---|---|---|---|\n";
    for (const MethodSummary& s : ms) {
      const HooverTotals& t = s.totals[i];
      m << "| " << s.name << " | " << pct(t.correct_fraction()) << " | " << pct(t.over_fraction()) << " | "
        << pct(t.under_fraction()) << " | " << pct(t.missed_fraction()) << " | " << pct(t.noise_fraction()) << " | "
        << t.gt_regions << " | " << t.ms_regions << " | " << s.rightmost_front_correct << "/"
        << s.rightmost_front_scenes << " | " << fx3(s.median_ms) << " |\n";
    }
  }
  m << "\n## Correct detection at T = 0.8 by kind of ground-truth region, % (regions)\n\n| method |";
  for (int g = 0; g < kNumCategories; ++g) m << " " << gt_category_name(g) << " |";
  m << "\n|---|";
  for (int g = 0; g < kNumCategories; ++g) m << "---|";
  m << "\n";
  for (const MethodSummary& s : ms) {
    m << "| " << s.name << " |";
    for (size_t g = 0; g < size_t(kNumCategories); ++g)
      m << " " << pct(s.category_regions[g] ? double(s.category_correct[g]) / double(s.category_regions[g]) : 0.0)
        << " (" << s.category_regions[g] << ") |";
    m << "\n";
  }
  m << "\nNotes: T = 0.5 is evaluated at 0.500001 (Hoover's T must exceed 0.5). Timings are wall clock on a shared "
       "machine.";
  if (c.steep_curvature > 0)
    m << " god = GoD as bws_detector is configured (god.jump_min_curvature " << c.god.god.jump_min_curvature
      << "); god_steep = the same with god.jump_min_curvature " << c.steep_curvature
      << " (a pixel is a jump edge only where the disparity also bends: steep planes keep their direction).";
  m << "\n";
  return m.str();
}

cv::Mat scene_picture(const RangeScene& scene, const SceneEval& e) {
  const int tw = 320, th = 240, bar = 22;
  const auto tile = [&](const cv::Mat& rgb, const std::string& title) {
    cv::Mat t(th + bar, tw, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::Mat r;
    cv::resize(rgb, r, cv::Size(tw, th), 0, 0, cv::INTER_NEAREST);
    r.copyTo(t(cv::Rect(0, bar, tw, th)));
    cv::putText(t, title, {4, 16}, cv::FONT_HERSHEY_SIMPLEX, 0.42, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    return t;
  };
  const auto disp_rgb = [](const cv::Mat& d) {
    cv::Mat v(d.size(), CV_8UC3, cv::Scalar(0, 0, 0));
    double lo = 1e9, hi = -1e9;
    for (int y = 0; y < d.rows; ++y)
      for (int x = 0; x < d.cols; ++x) {
        const float f = d.at<float>(y, x);
        if (std::isfinite(f)) lo = std::min(lo, double(f)), hi = std::max(hi, double(f));
      }
    for (int y = 0; y < d.rows; ++y)
      for (int x = 0; x < d.cols; ++x) {
        const float f = d.at<float>(y, x);
        if (!std::isfinite(f)) continue;
        const uchar g = uchar(40 + 215 * (f - lo) / std::max(1e-6, hi - lo));
        v.at<cv::Vec3b>(y, x) = cv::Vec3b(g, g, g);
      }
    return v;
  };
  size_t t08 = 0;  // index of T = 0.8 if present (titles)
  if (!e.runs.empty())
    for (size_t i = 0; i < e.runs[0].hoover.size(); ++i)
      if (std::fabs(e.runs[0].hoover[i].tolerance - 0.8) < 1e-9) t08 = i;
  const auto run_tile = [&](const MethodRun& r) {
    const HooverResult& h = r.hoover.at(t08);
    char b[160];
    std::snprintf(b, sizeof b, "%s: T%.1f c%d o%d u%d m%d n%d /%d", r.name.c_str(), h.tolerance, h.correct, h.over,
                  h.under_gt_regions, h.missed, h.noise, h.num_gt());
    return tile(colorize_labels(r.labels), b);
  };
  std::vector<cv::Mat> row1 = {
      tile(scene.left_rgb, "left image, seed " + std::to_string(e.seed)),
      tile(colorize_labels(scene.gt_labels), "ground truth: " + std::to_string(e.gt_regions) + " regions")};
  std::vector<cv::Mat> row2 = {tile(disp_rgb(e.disparity_true), "true-depth disparity"),
                               e.disparity_stereo.empty()
                                   ? tile(cv::Mat(th, tw, CV_8UC3, cv::Scalar(255, 255, 255)), "")
                                   : tile(disp_rgb(e.disparity_stereo), "stereo (block matching) disparity")};
  for (const MethodRun& r : e.runs) (r.name.find("_stereo") == std::string::npos ? row1 : row2).push_back(run_tile(r));
  while (row2.size() < row1.size()) row2.push_back(tile(cv::Mat(th, tw, CV_8UC3, cv::Scalar(255, 255, 255)), ""));
  while (row1.size() < row2.size()) row1.push_back(tile(cv::Mat(th, tw, CV_8UC3, cv::Scalar(255, 255, 255)), ""));
  // Third row: zoom on the books (bounding box of the GT regions owned by books), true source.
  cv::Rect books;
  for (const GtRegion& g : scene.regions) {
    if (g.owner < 0) continue;
    cv::Mat mask = scene.gt_labels == g.label;
    const cv::Rect r = cv::boundingRect(mask);
    books = books.area() ? (books | r) : r;
  }
  std::vector<cv::Mat> row3;
  if (books.area() > 0) {
    const cv::Point2f c(books.x + books.width / 2.f, books.y + books.height / 2.f);
    const int w = std::max(books.width + 20, (books.height + 20) * 4 / 3), h = w * 3 / 4;
    cv::Rect z(int(c.x) - w / 2, int(c.y) - h / 2, w, h);
    z &= cv::Rect(0, 0, scene.gt_labels.cols, scene.gt_labels.rows);
    row3.push_back(tile(scene.left_rgb(z), "zoom: books"));
    row3.push_back(tile(colorize_labels(scene.gt_labels(z)), "zoom: ground truth"));
    for (const MethodRun& r : e.runs)
      if (r.name.find("_stereo") == std::string::npos)
        row3.push_back(tile(colorize_labels(r.labels(z)), "zoom: " + r.name));
    while (row3.size() < row1.size()) row3.push_back(tile(cv::Mat(th, tw, CV_8UC3, cv::Scalar(255, 255, 255)), ""));
  }
  cv::Mat a, b, out;
  cv::hconcat(row1, a);
  cv::hconcat(row2, b);
  cv::vconcat(a, b, out);
  if (!row3.empty() && row3.size() == row1.size()) {
    cv::Mat c3;
    cv::hconcat(row3, c3);
    cv::vconcat(out, c3, out);
  }
  return out;
}

}  // namespace bookgrasp::eval_segmentation
