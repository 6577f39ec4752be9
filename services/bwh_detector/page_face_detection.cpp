#include "services/bwh_detector/page_face_detection.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace bookgrasp {

PageFaceParams PageFaceParams::from_config(const Config& cfg) {
  PageFaceParams p;
  p.blur_sigma_px = cfg.get_double("blur_sigma_px", 0.0, 10.0);
  p.max_saturation = cfg.get_int("max_saturation", 1, 255);
  p.min_value = cfg.get_int("min_value", 0, 254);
  p.open_px = cfg.get_int("open_px", 0, 10);
  p.close_vertical_px = cfg.get_int("close_vertical_px", 0, 500);
  p.split_step_px = cfg.get_double("split_step_px", 0.5, 1000.0);
  p.ignore_bottom_px = cfg.get_int("ignore_bottom_px", 0, 1000);
  p.bottom_reach_px = cfg.get_int("bottom_reach_px", 0, 1000);
  p.min_width_px = cfg.get_double("min_width_px", 1.0, 10000.0);
  p.max_width_px = cfg.get_double("max_width_px", 1.0, 10000.0);
  if (p.max_width_px < p.min_width_px)
    throw ConfigError(cfg.source() + ": " + cfg.path_of("max_width_px") + " must be >= min_width_px");
  p.min_height_px = cfg.get_double("min_height_px", 1.0, 10000.0);
  p.min_fill_ratio = cfg.get_double("min_fill_ratio", 0.0, 1.0);
  p.top_margin_px = cfg.get_int("top_margin_px", 0, 100);
  p.fit_trim_px = cfg.get_double("fit_trim_px", 0.1, 100.0);
  p.side_fit_rows_px = cfg.get_double("side_fit_rows_px", 3.0, 10000.0);
  return p;
}

namespace {

/// u = a t + b by least squares, trimmed three times at `trim` (and at 3x the RMS first).
bool fit_line(std::vector<cv::Point2d> pts, double trim, double* a, double* b) {
  for (int round = 0; round < 4; ++round) {
    if (pts.size() < 3) return false;
    double st = 0, su = 0, stt = 0, stu = 0;
    const double n = static_cast<double>(pts.size());
    for (const auto& p : pts) {
      st += p.x;
      su += p.y;
      stt += p.x * p.x;
      stu += p.x * p.y;
    }
    const double den = n * stt - st * st;
    if (std::abs(den) < 1e-9) return false;
    *a = (n * stu - st * su) / den;
    *b = (su - *a * st) / n;
    double rms = 0;
    for (const auto& p : pts) rms += std::pow(p.y - (*a * p.x + *b), 2);
    rms = std::sqrt(rms / n);
    const double limit = round < 2 ? std::max(trim, 2.5 * rms) : trim;
    std::vector<cv::Point2d> keep;
    for (const auto& p : pts)
      if (std::abs(p.y - (*a * p.x + *b)) <= limit) keep.push_back(p);
    if (keep.size() == pts.size() && round >= 2) return true;
    pts.swap(keep);
  }
  return pts.size() >= 3;
}

}  // namespace

BookDetection detect_books_page_faces(const cv::Mat& rgb, const PageFaceParams& p) {
  if (rgb.empty() || rgb.type() != CV_8UC3)
    throw std::invalid_argument("detect_books_page_faces: expected a non-empty CV_8UC3 RGB image");
  BookDetection out;
  cv::Mat smooth = rgb;
  if (p.blur_sigma_px > 0) cv::GaussianBlur(rgb, smooth, cv::Size(0, 0), p.blur_sigma_px);
  cv::Mat hsv;
  cv::cvtColor(smooth, hsv, cv::COLOR_RGB2HSV);
  std::vector<cv::Mat> ch;
  cv::split(hsv, ch);
  cv::Mat mask = (ch[1] < p.max_saturation) & (ch[2] > p.min_value);
  const int bottom = std::max(1, rgb.rows - p.ignore_bottom_px);  // rows >= bottom are ignored
  mask.rowRange(bottom, rgb.rows).setTo(0);
  if (p.open_px > 0)
    cv::morphologyEx(mask, mask, cv::MORPH_OPEN,
                     cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * p.open_px + 1, 2 * p.open_px + 1)));

  if (p.close_vertical_px > 1)
    cv::morphologyEx(mask, mask, cv::MORPH_CLOSE,
                     cv::getStructuringElement(cv::MORPH_RECT, cv::Size(1, p.close_vertical_px)));
  mask.rowRange(bottom, rgb.rows).setTo(0);

  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 4, CV_32S);
  std::string last_reason = "no bright unsaturated (page) region at all (max_saturation, min_value)";
  for (int i = 1; i < n; ++i) {
    const int bx = stats.at<int>(i, cv::CC_STAT_LEFT), by = stats.at<int>(i, cv::CC_STAT_TOP);
    const int bw = stats.at<int>(i, cv::CC_STAT_WIDTH), bh = stats.at<int>(i, cv::CC_STAT_HEIGHT);
    const int area = stats.at<int>(i, cv::CC_STAT_AREA);
    if (area < 30) continue;
    BookCandidate c;
    c.id = static_cast<int>(out.candidates.size());
    c.bbox = cv::Rect(bx, by, bw, bh);
    c.height_px = bh;
    auto reject = [&](const std::string& why) {
      c.reject_reason = why;
      last_reason = why;
      out.candidates.push_back(c);
    };
    if (by + bh < bottom - p.bottom_reach_px) {
      reject("does not reach down to the shelf (not a fore-edge: marker, backdrop, print)");
      continue;
    }
    // Top-most pixel per column; runs of columns whose top edge is continuous.
    std::vector<int> top_of(static_cast<size_t>(bw), -1);
    for (int x = bx; x < bx + bw; ++x)
      for (int y = by; y < by + bh; ++y)
        if (labels.at<int>(y, x) == i) {
          top_of[static_cast<size_t>(x - bx)] = y;
          break;
        }
    std::vector<std::pair<int, int>> runs;  // [first, last] column offsets
    for (int j = 0; j < bw; ++j) {
      const int t = top_of[static_cast<size_t>(j)];
      if (t < 0) continue;
      if (!runs.empty() && runs.back().second == j - 1 &&
          std::abs(t - top_of[static_cast<size_t>(j - 1)]) <= p.split_step_px) {
        runs.back().second = j;
      } else {
        runs.emplace_back(j, j);
      }
    }
    for (size_t r = 0; r < runs.size(); ++r) {
      const bool rightmost_run = r + 1 == runs.size();
      BookCandidate rc = c;
      rc.id = static_cast<int>(out.candidates.size());
      rc.num_merged = static_cast<int>(runs.size());
      int run_top = by + bh;
      std::vector<cv::Point2d> top_pts;
      for (int j = runs[r].first; j <= runs[r].second; ++j) {
        const int t = top_of[static_cast<size_t>(j)];
        run_top = std::min(run_top, t);
        top_pts.emplace_back(bx + j, t - 0.5);  // boundary between pixel t-1 and t
      }
      rc.bbox = cv::Rect(bx + runs[r].first, run_top, runs[r].second - runs[r].first + 1, by + bh - run_top);
      rc.width_px = runs[r].second - runs[r].first + 1;
      rc.height_px = by + bh - run_top;
      int run_area = 0;
      for (int y = rc.bbox.y; y < rc.bbox.y + rc.bbox.height; ++y)
        for (int x = rc.bbox.x; x < rc.bbox.x + rc.bbox.width; ++x) run_area += labels.at<int>(y, x) == i;
      rc.fill_ratio = static_cast<double>(run_area) / (rc.width_px * rc.height_px);
      auto reject_run = [&](const std::string& why) {
        rc.reject_reason = why;
        last_reason = why;
        out.candidates.push_back(rc);
      };
      // Per run, not per region: a fore-edge whose top is in view stays a candidate when it touches a taller
      // neighbour's that runs out of the image (far_cart seed 6: one region, rejected whole, every other frame).
      if (run_top <= p.top_margin_px) {
        reject_run("touches the top border (no book top in view)");
        continue;
      }
      if (rc.height_px < p.min_height_px) {
        reject_run("lower than min_height_px");
        continue;
      }
      if (rc.width_px < p.min_width_px) {
        reject_run("narrower than min_width_px (cover strip, gap or print)");
        continue;
      }
      if (rc.width_px > p.max_width_px) {
        reject_run("wider than max_width_px (background or several books)");
        continue;
      }
      if (rc.fill_ratio < p.min_fill_ratio) {
        reject_run("not a quadrilateral (fill ratio below min_fill_ratio)");
        continue;
      }
      double ta = 0, tb = 0;
      if (!fit_line(top_pts, p.fit_trim_px, &ta, &tb)) {
        reject_run("top edge could not be fitted");
        continue;
      }
      double x = bx + runs[r].second + 0.5;  // a step to a taller neighbour: the run's last column
      if (rightmost_run) {
        // Right side: right-most mask pixel per row below the run's top (skip the rounded corner).
        std::vector<cv::Point2d> side;
        for (int y = run_top + 3; y < std::min(by + bh, run_top + static_cast<int>(p.side_fit_rows_px) + 3); ++y) {
          const int* row = labels.ptr<int>(y);
          for (int xx = bx + bw - 1; xx >= bx; --xx)
            if (row[xx] == i) {
              side.emplace_back(y, xx + 0.5);  // boundary between pixel xx and xx+1
              break;
            }
        }
        double sa = 0, sb = 0;
        if (!fit_line(side, p.fit_trim_px, &sa, &sb)) {
          reject_run("right side could not be fitted");
          continue;
        }
        const double den = 1.0 - ta * sa;
        if (std::abs(den) < 1e-6) {
          reject_run("top edge parallel to the side");
          continue;
        }
        x = (sa * tb + sb) / den;
      }
      rc.corner_r = cv::Point2d(x, ta * x + tb);
      const double xl = bx + runs[r].first - 0.5;
      rc.corner_l = cv::Point2d(xl, ta * xl + tb);
      rc.slope_rad = std::atan(ta);
      rc.refined = true;
      rc.accepted = true;
      out.candidates.push_back(rc);
    }
  }
  for (const auto& c : out.candidates)
    if (c.accepted) out.ranking.push_back(c.id);
  std::sort(out.ranking.begin(), out.ranking.end(), [&](int a, int b) {
    return out.candidates[static_cast<size_t>(a)].corner_r.x > out.candidates[static_cast<size_t>(b)].corner_r.x;
  });
  out.found = !out.ranking.empty();
  if (!out.found) out.failure_reason = "no fore-edge passes the book criteria; last: " + last_reason;
  return out;
}

}  // namespace bookgrasp
