#include "services/bswh_detector/stripe_detection.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace bookgrasp {

StripeDetectionParams StripeDetectionParams::from_config(const Config& cfg) {
  StripeDetectionParams p;
  p.blur_sigma_px = cfg.get_double("blur_sigma_px", 0.0, 10.0);
  p.background_scale = cfg.get_int("background_scale", 1, 32);
  p.background_kernel_px = cfg.get_int("background_kernel_px", 8, 1024);
  p.dark_ratio = cfg.get_double("dark_ratio", 0.05, 1.0);
  p.max_dark_value = cfg.get_int("max_dark_value", 1, 255);
  p.min_length_px = cfg.get_int("min_length_px", 5, 10000);
  p.min_thickness_px = cfg.get_double("min_thickness_px", 1.0, 1000.0);
  p.max_thickness_px = cfg.get_double("max_thickness_px", 1.0, 1000.0);
  if (p.max_thickness_px < p.min_thickness_px) {
    throw ConfigError(cfg.source() + ": " + cfg.path_of("max_thickness_px") + " must be >= min_thickness_px");
  }
  p.max_angle_deg = cfg.get_double("max_angle_deg", 0.0, 60.0);
  p.edge_sigma_px = cfg.get_double("edge_sigma_px", 0.0, 10.0);
  p.canny_low = cfg.get_double("canny_low", 1.0, 1000.0);
  p.canny_high = cfg.get_double("canny_high", 1.0, 1000.0);
  p.border_margin_px = cfg.get_int("border_margin_px", 0, 100);
  p.end_side = cfg.get_choice("end_side", {"left", "right"});
  // Robustness keys (added later): optional, the defaults keep the earlier behaviour.
  if (cfg.has("ignore_bottom_rows")) p.ignore_bottom_rows = cfg.get_int("ignore_bottom_rows", 0, 4096);
  if (cfg.has("reject_touching_bottom")) p.reject_touching_bottom = cfg.get<bool>("reject_touching_bottom");
  if (cfg.has("min_band_fill")) p.min_band_fill = cfg.get_double("min_band_fill", 0.0, 1.0);
  if (cfg.has("expected_row_px")) p.expected_row_px = cfg.get_double("expected_row_px", -1.0, 10000.0);
  if (cfg.has("max_row_offset_px")) p.max_row_offset_px = cfg.get_double("max_row_offset_px", 1.0, 1e9);
  if (cfg.has("max_dark_spread")) p.max_dark_spread = cfg.get_int("max_dark_spread", 0, 255);
  if (cfg.has("background_kernel_width_px"))
    p.background_kernel_width_px = cfg.get_int("background_kernel_width_px", 0, 1024);
  return p;
}

double StripeDetection::centre_y_at(double x) const {
  const double dx = line_end.x - line_start.x;
  if (std::abs(dx) < 1e-9) return line_start.y;
  return line_start.y + (x - line_start.x) * (line_end.y - line_start.y) / dx;
}

cv::Mat max_channel(const cv::Mat& image) {
  if (image.empty()) throw std::invalid_argument("empty image");
  if (image.type() == CV_8UC1) return image;
  if (image.type() != CV_8UC3) throw std::invalid_argument("image must be CV_8UC1 or CV_8UC3");
  cv::Mat ch[3];
  cv::split(image, ch);
  cv::Mat v;
  cv::max(ch[0], ch[1], v);
  cv::max(v, ch[2], v);
  return v;
}

namespace {

struct Segment {
  double slope = 0.0, intercept = 0.0;  // y = slope * x + intercept
  double vertical_thickness = 0.0;
  int x_min = 0, x_max = 0, length = 0;
};

// Least-squares y = a x + b.
bool fit_line_y_of_x(const std::vector<cv::Point2d>& pts, double* a, double* b) {
  if (pts.size() < 2) return false;
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const auto& p : pts) {
    sx += p.x;
    sy += p.y;
    sxx += p.x * p.x;
    sxy += p.x * p.y;
  }
  const double n = static_cast<double>(pts.size());
  const double d = n * sxx - sx * sx;
  if (std::abs(d) < 1e-9) return false;
  *a = (n * sxy - sx * sy) / d;
  *b = (sy - *a * sx) / n;
  return true;
}

}  // namespace

StripeDetection detect_stripe(const cv::Mat& image, const StripeDetectionParams& p) {
  if (image.empty()) throw std::invalid_argument("detect_stripe: empty image");
  StripeDetection out;
  const cv::Mat v = max_channel(image);
  cv::Mat smooth;
  if (p.blur_sigma_px > 0) {
    cv::GaussianBlur(v, smooth, cv::Size(0, 0), p.blur_sigma_px);
  } else {
    smooth = v;
  }

  // Local background: dark structures thinner than the closing kernel removed.
  const int scale = std::max(1, p.background_scale);
  cv::Mat small;
  cv::resize(smooth, small, cv::Size(std::max(1, v.cols / scale), std::max(1, v.rows / scale)), 0, 0, cv::INTER_AREA);
  const int k = std::max(3, (p.background_kernel_px / scale) | 1);
  const int kw = p.background_kernel_width_px > 0 ? std::max(1, (p.background_kernel_width_px / scale) | 1) : k;
  cv::morphologyEx(small, small, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(kw, k)));
  cv::blur(small, small, cv::Size(3, 3));
  cv::Mat background;
  cv::resize(small, background, v.size(), 0, 0, cv::INTER_LINEAR);

  // Threshold segmentation: dark against the local background and dark in absolute terms.
  cv::Mat threshold;
  background.convertTo(threshold, CV_8U, p.dark_ratio);
  cv::Mat dark = (smooth < threshold) & (smooth < p.max_dark_value);
  if (image.type() == CV_8UC3 && p.max_dark_spread < 255) {
    // Colour spread of each pixel, smoothed like the value: noise on a black stripe stays a few grey levels.
    // Only dark coloured areas at least 5 px across count: the rims where the stripe blends into a coloured
    // background are dark and coloured too, and taking them off would thin the band.
    cv::Mat ch[3], low, spread;
    cv::split(image, ch);
    cv::min(ch[0], ch[1], low);
    cv::min(low, ch[2], low);
    cv::subtract(v, low, spread);
    if (p.blur_sigma_px > 0) cv::GaussianBlur(spread, spread, cv::Size(0, 0), p.blur_sigma_px);
    cv::Mat coloured = (spread > p.max_dark_spread) & dark;
    cv::morphologyEx(coloured, coloured, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5)));
    dark &= ~coloured;
  }
  const int run = std::max(5, std::min(p.min_length_px, 41) / 2 * 2 + 1);
  const int usable_rows = std::max(1, v.rows - p.ignore_bottom_rows);
  if (usable_rows < v.rows) dark.rowRange(usable_rows, v.rows).setTo(0);
  cv::morphologyEx(dark, dark, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(run, 1)));

  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(dark, labels, stats, centroids, 8, CV_32S);
  const double max_tan = std::tan(p.max_angle_deg * CV_PI / 180.0);
  std::vector<Segment> segments;
  std::string last_reject = "no dark horizontal region at all (dark_ratio, max_dark_value, max_dark_spread)";
  for (int i = 1; i < n; ++i) {
    const int bx = stats.at<int>(i, cv::CC_STAT_LEFT), by = stats.at<int>(i, cv::CC_STAT_TOP);
    const int bw = stats.at<int>(i, cv::CC_STAT_WIDTH), bh = stats.at<int>(i, cv::CC_STAT_HEIGHT);
    if (bw < p.min_length_px) {
      last_reject = "darkest horizontal region is only " + std::to_string(bw) + " px long (min_length_px " +
                    std::to_string(p.min_length_px) + ")";
      continue;
    }
    std::vector<int> count(static_cast<size_t>(bw), 0);
    std::vector<double> ysum(static_cast<size_t>(bw), 0.0);
    for (int y = by; y < by + bh; ++y) {
      const int* row = labels.ptr<int>(y);
      for (int x = bx; x < bx + bw; ++x) {
        if (row[x] == i) {
          ++count[static_cast<size_t>(x - bx)];
          ysum[static_cast<size_t>(x - bx)] += y;
        }
      }
    }
    std::vector<int> sorted;
    for (int c : count)
      if (c > 0) sorted.push_back(c);
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
    const double median = sorted[sorted.size() / 2];
    std::vector<cv::Point2d> centres;
    int x_min = -1, x_max = -1;
    for (int j = 0; j < bw; ++j) {
      const int c = count[static_cast<size_t>(j)];
      if (c >= 0.5 * median && c <= 1.5 * median + 1) {
        centres.emplace_back(bx + j, ysum[static_cast<size_t>(j)] / c);
        if (x_min < 0) x_min = bx + j;
        x_max = bx + j;
      }
    }
    Segment s;
    if (!fit_line_y_of_x(centres, &s.slope, &s.intercept)) continue;
    if (std::abs(s.slope) > max_tan) {
      last_reject =
          "dark region at angle " + std::to_string(std::atan(s.slope) * 180 / CV_PI) + " deg exceeds max_angle_deg";
      continue;
    }
    s.vertical_thickness = median;
    const double perp = median / std::sqrt(1.0 + s.slope * s.slope);
    if (perp < p.min_thickness_px || perp > p.max_thickness_px) {
      last_reject = "dark horizontal region is " + std::to_string(perp) + " px thick, outside [min_thickness_px, " +
                    "max_thickness_px]";
      continue;
    }
    s.x_min = x_min;
    s.x_max = x_max;
    s.length = static_cast<int>(centres.size());
    if (s.length < p.min_length_px) continue;
    if (p.reject_touching_bottom) {
      // The band itself (centre line +- half its thickness) reaching the bottom: a shadow on the shelf or
      // beside the fingers. (A stripe joined to a dark cover that reaches the bottom is kept: the cover's
      // columns are not band columns.)
      const double low = std::max(s.slope * x_min, s.slope * x_max) + s.intercept + 0.5 * median;
      if (low >= usable_rows - 2) {
        last_reject = "dark horizontal band touches the image bottom (a shadow on the shelf or the fingers)";
        continue;
      }
    }
    if (s.length < p.min_band_fill * bw) {
      last_reject = "dark region is not a band: " + std::to_string(s.length) + " of " + std::to_string(bw) +
                    " columns have the band's thickness (min_band_fill)";
      continue;
    }
    if (p.expected_row_px >= 0) {
      const double row = s.slope * 0.5 * (v.cols - 1) + s.intercept;
      if (std::abs(row - p.expected_row_px) > p.max_row_offset_px) {
        last_reject = "dark horizontal band at row " + std::to_string(static_cast<int>(std::lround(row))) +
                      ", more than max_row_offset_px from expected_row_px";
        continue;
      }
    }
    segments.push_back(s);
  }
  if (segments.empty()) {
    out.failure_reason = "black stripe not visible: " + last_reject;
    return out;
  }
  const bool left = p.end_side == "left";
  // The segment nearest the side the robot comes from (opposite end_side), the longest on ties.
  const Segment best = *std::max_element(segments.begin(), segments.end(), [&](const Segment& a, const Segment& b) {
    const int ka = left ? a.x_max : -a.x_min, kb = left ? b.x_max : -b.x_min;
    if (std::abs(ka - kb) > 2) return ka < kb;
    return a.length < b.length;
  });
  out.found = true;
  out.angle_rad = std::atan(best.slope);
  out.thickness_px = best.vertical_thickness * std::cos(out.angle_rad);
  out.line_start = {static_cast<double>(best.x_min), best.slope * best.x_min + best.intercept};
  out.line_end = {static_cast<double>(best.x_max), best.slope * best.x_max + best.intercept};

  const int x0 = left ? best.x_min : best.x_max;
  if ((left && x0 <= p.border_margin_px) || (!left && x0 >= v.cols - 1 - p.border_margin_px)) {
    out.failure_reason = std::string("the stripe reaches the ") + (left ? "left" : "right") +
                         " image border: its end is outside the image";
    return out;
  }

  // Refine the end on Canny edges across the stripe's inner rows.
  const double yc = best.slope * x0 + best.intercept;
  const double half = std::max(1.0, 0.3 * best.vertical_thickness);
  const int w = static_cast<int>(std::max(6.0, best.vertical_thickness));
  const cv::Rect roi =
      cv::Rect(x0 - w - 2, static_cast<int>(std::floor(yc - half)) - 2, 2 * w + 5, static_cast<int>(2 * half) + 6) &
      cv::Rect(0, 0, v.cols, v.rows);
  std::vector<cv::Point2d> edge_points;
  if (roi.width > 4 && roi.height > 4) {
    cv::Mat patch;
    if (p.edge_sigma_px > 0) {
      // Blur a slightly larger window so the patch has no border artefacts.
      const cv::Rect outer =
          cv::Rect(roi.x - 4, roi.y - 4, roi.width + 8, roi.height + 8) & cv::Rect(0, 0, v.cols, v.rows);
      cv::Mat blurred;
      cv::GaussianBlur(v(outer), blurred, cv::Size(0, 0), p.edge_sigma_px);
      patch = blurred(cv::Rect(roi.x - outer.x, roi.y - outer.y, roi.width, roi.height)).clone();
    } else {
      patch = v(roi).clone();
    }
    cv::Mat edges, gx, gy;
    cv::Canny(patch, edges, p.canny_low, p.canny_high, 3, true);
    cv::Sobel(patch, gx, CV_32F, 1, 0, 3);
    cv::Sobel(patch, gy, CV_32F, 0, 1, 3);
    for (int ry = 1; ry < roi.height - 1; ++ry) {
      const double y = roi.y + ry;
      if (std::abs(y - (best.slope * x0 + best.intercept)) > half) continue;
      // Scan from inside the stripe outwards: the first edge of the right sign is the
      // stripe's own end (a dark cover beside it would give a second edge further out).
      int best_x = -1;
      const int inside = std::clamp(x0 + (left ? w : -w) - roi.x, 1, roi.width - 2);
      const int step = left ? -1 : 1;
      for (int rx = inside; rx >= 1 && rx <= roi.width - 2; rx += step) {
        if (!edges.at<uint8_t>(ry, rx)) continue;
        const float g = gx.at<float>(ry, rx);
        if (std::abs(g) <= std::abs(gy.at<float>(ry, rx))) continue;
        if (left ? g >= 0 : g <= 0) continue;  // bright outside, dark stripe inside
        best_x = rx;
        break;
      }
      if (best_x < 0) continue;
      const double gm = std::abs(gx.at<float>(ry, best_x - 1)), g0 = std::abs(gx.at<float>(ry, best_x)),
                   gp = std::abs(gx.at<float>(ry, best_x + 1));
      const double den = gm - 2 * g0 + gp;
      const double off = std::abs(den) > 1e-6 ? std::clamp(0.5 * (gm - gp) / den, -0.5, 0.5) : 0.0;
      edge_points.emplace_back(roi.x + best_x + off, y);
    }
  }
  if (edge_points.size() >= 3) {
    // x = a y + b through the edge points, intersected with y = m x + c.
    std::vector<cv::Point2d> swapped;
    for (const auto& e : edge_points) swapped.emplace_back(e.y, e.x);
    double a = 0, b = 0;
    if (!fit_line_y_of_x(swapped, &a, &b)) {
      a = 0;
      b = 0;
      for (const auto& e : edge_points) b += e.x / static_cast<double>(edge_points.size());
    }
    const double x = (a * best.intercept + b) / (1.0 - a * best.slope);
    out.end = {x, best.slope * x + best.intercept};
    out.end_edge_support = static_cast<int>(edge_points.size());
  } else {
    out.end = {x0 + (left ? -0.5 : 0.5), yc};
    out.end_edge_support = 0;
  }
  out.end_found = true;
  return out;
}

}  // namespace bookgrasp
