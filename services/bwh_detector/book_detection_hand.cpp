#include "services/bwh_detector/book_detection_hand.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace bookgrasp {

BookDetectionParams BookDetectionParams::from_config(const Config& cfg) {
  BookDetectionParams p;
  p.illumination_sigma_px = cfg.get_double("illumination_sigma_px", 2.0, 1000.0);
  p.illumination_scale = cfg.get_int("illumination_scale", 1, 32);
  p.blur_sigma_px = cfg.get_double("blur_sigma_px", 0.0, 10.0);
  p.canny_low = cfg.get_double("canny_low", 1.0, 1000.0);
  p.canny_high = cfg.get_double("canny_high", 1.0, 1000.0);
  p.edge_dilate_px = cfg.get_int("edge_dilate_px", 0, 5);
  p.min_piece_area_px = cfg.get_int("min_piece_area_px", 1, 1000000);
  p.min_width_px = cfg.get_double("min_width_px", 1.0, 10000.0);
  p.max_width_px = cfg.get_double("max_width_px", 1.0, 10000.0);
  if (p.max_width_px < p.min_width_px) {
    throw ConfigError(cfg.source() + ": " + cfg.path_of("max_width_px") + " must be >= min_width_px");
  }
  p.min_height_px = cfg.get_double("min_height_px", 1.0, 10000.0);
  p.min_fill_ratio = cfg.get_double("min_fill_ratio", 0.0, 1.0);
  p.max_lean_deg = cfg.get_double("max_lean_deg", 0.0, 45.0);
  p.merge_max_offset_px = cfg.get_double("merge_max_offset_px", 0.0, 100.0);
  p.merge_max_angle_deg = cfg.get_double("merge_max_angle_deg", 0.0, 45.0);
  p.merge_max_gap_px = cfg.get_double("merge_max_gap_px", 0.0, 200.0);
  p.refine_band_px = cfg.get_double("refine_band_px", 0.0, 100.0);
  p.refine_sigma_px = cfg.get_double("refine_sigma_px", 0.0, 10.0);
  p.refine_canny_low = cfg.get_double("refine_canny_low", 1.0, 1000.0);
  p.refine_canny_high = cfg.get_double("refine_canny_high", 1.0, 1000.0);
  p.border_margin_px = cfg.get_int("border_margin_px", 0, 100);
  p.use_stripe = cfg.get<bool>("use_stripe");
  p.stripe = StripeDetectionParams::from_config(cfg.child("stripe"));
  return p;
}

namespace {

/// A line u = a * t + b (x of y for sides, y of x for top/bottom edges).
struct Line {
  double a = 0.0, b = 0.0;
  bool ok = false;
  double at(double t) const { return a * t + b; }
};

/// Least squares with two rounds of trimming (residual > trim_px dropped).
Line robust_fit(const std::vector<cv::Point2d>& pts /* (t, u) */, double trim_px) {
  Line l;
  std::vector<cv::Point2d> use = pts;
  for (int round = 0; round < 3; ++round) {
    if (use.size() < 2) return l;
    double st = 0, su = 0, stt = 0, stu = 0;
    for (const auto& p : use) {
      st += p.x;
      su += p.y;
      stt += p.x * p.x;
      stu += p.x * p.y;
    }
    const double n = static_cast<double>(use.size());
    const double d = n * stt - st * st;
    if (std::abs(d) < 1e-9) {
      l.a = 0;
      l.b = su / n;
    } else {
      l.a = (n * stu - st * su) / d;
      l.b = (su - l.a * st) / n;
    }
    l.ok = true;
    if (round == 2) break;
    std::vector<double> res;
    for (const auto& p : use) res.push_back(std::abs(p.y - l.at(p.x)));
    std::vector<double> sorted = res;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
    const double lim = std::max(trim_px, 2.5 * sorted[sorted.size() / 2]);
    std::vector<cv::Point2d> kept;
    for (size_t i = 0; i < use.size(); ++i)
      if (res[i] <= lim) kept.push_back(use[i]);
    if (kept.size() == use.size()) break;
    use.swap(kept);
  }
  return l;
}

/// A region (or several merged) with its outline per row and per column.
struct Piece {
  int y0 = 0, x0 = 0;
  std::vector<int> xmin, xmax;  // per row y0 + i (-1 = empty)
  std::vector<int> ymin, ymax;  // per column x0 + j (-1 = empty)
  int area = 0;
  int num_merged = 1;
  bool alive = true;
  // Fits.
  Line left, right, top;     // left/right: x(y); top: y(x)
  double top_y = 0, bottom_y = 0, centre_x = 0, width = 0, height = 0;

  int y1() const { return y0 + static_cast<int>(xmin.size()) - 1; }
  int x1() const { return x0 + static_cast<int>(ymin.size()) - 1; }
};

void fit_piece(Piece& p) {
  int ylo = -1, yhi = -1;
  for (size_t i = 0; i < p.xmin.size(); ++i) {
    if (p.xmin[i] < 0) continue;
    if (ylo < 0) ylo = p.y0 + static_cast<int>(i);
    yhi = p.y0 + static_cast<int>(i);
  }
  const double h = yhi - ylo + 1;
  std::vector<cv::Point2d> lp, rp;
  for (size_t i = 0; i < p.xmin.size(); ++i) {
    const int y = p.y0 + static_cast<int>(i);
    if (p.xmin[i] < 0 || y < ylo + 0.1 * h || y > yhi - 0.1 * h) continue;
    lp.emplace_back(y, p.xmin[i]);
    rp.emplace_back(y, p.xmax[i]);
  }
  p.left = robust_fit(lp, 1.5);
  p.right = robust_fit(rp, 1.5);
  const double ymid = 0.5 * (ylo + yhi);
  const double xl = p.left.ok ? p.left.at(ymid) : p.x0, xr = p.right.ok ? p.right.at(ymid) : p.x1();
  p.centre_x = 0.5 * (xl + xr);
  p.width = xr - xl + 1;
  std::vector<cv::Point2d> tp;
  double bottom_sum = 0;
  int bottom_n = 0;
  for (size_t j = 0; j < p.ymin.size(); ++j) {
    const int x = p.x0 + static_cast<int>(j);
    if (p.ymin[j] < 0 || x < xl + 0.15 * p.width || x > xr - 0.15 * p.width) continue;
    tp.emplace_back(x, p.ymin[j]);
    bottom_sum += p.ymax[j];
    ++bottom_n;
  }
  p.top = robust_fit(tp, 1.5);
  p.top_y = p.top.ok ? p.top.at(p.centre_x) : ylo;
  p.bottom_y = bottom_n ? bottom_sum / bottom_n : yhi;
  p.height = p.bottom_y - p.top_y + 1;
}

void absorb(Piece& a, Piece& b) {
  const int y0 = std::min(a.y0, b.y0), y1 = std::max(a.y1(), b.y1());
  const int x0 = std::min(a.x0, b.x0), x1 = std::max(a.x1(), b.x1());
  std::vector<int> xmin(static_cast<size_t>(y1 - y0 + 1), -1), xmax(xmin.size(), -1);
  std::vector<int> ymin(static_cast<size_t>(x1 - x0 + 1), -1), ymax(ymin.size(), -1);
  for (const Piece* p : {&a, &b}) {
    for (size_t i = 0; i < p->xmin.size(); ++i) {
      if (p->xmin[i] < 0) continue;
      const size_t k = static_cast<size_t>(p->y0 + static_cast<int>(i) - y0);
      xmin[k] = xmin[k] < 0 ? p->xmin[i] : std::min(xmin[k], p->xmin[i]);
      xmax[k] = std::max(xmax[k], p->xmax[i]);
    }
    for (size_t j = 0; j < p->ymin.size(); ++j) {
      if (p->ymin[j] < 0) continue;
      const size_t k = static_cast<size_t>(p->x0 + static_cast<int>(j) - x0);
      ymin[k] = ymin[k] < 0 ? p->ymin[j] : std::min(ymin[k], p->ymin[j]);
      ymax[k] = std::max(ymax[k], p->ymax[j]);
    }
  }
  a.y0 = y0;
  a.x0 = x0;
  a.xmin.swap(xmin);
  a.xmax.swap(xmax);
  a.ymin.swap(ymin);
  a.ymax.swap(ymax);
  a.area += b.area;
  a.num_merged += b.num_merged;
  b.alive = false;
  fit_piece(a);
}

/// True if `up` (above) and `down` are one book: side edges continue in position and slope.
bool same_book(const Piece& up, const Piece& down, const BookDetectionParams& p) {
  if (!up.left.ok || !up.right.ok || !down.left.ok || !down.right.ok) return false;
  const double overlap = std::min(up.x1(), down.x1()) - std::max(up.x0, down.x0);
  if (overlap < 0.5 * std::min(up.width, down.width)) return false;
  const double gap = down.top_y - up.bottom_y;
  if (gap > p.merge_max_gap_px) return false;
  const double yj = 0.5 * (up.bottom_y + down.top_y);
  if (std::abs(up.left.at(yj) - down.left.at(yj)) > p.merge_max_offset_px) return false;
  if (std::abs(up.right.at(yj) - down.right.at(yj)) > p.merge_max_offset_px) return false;
  const double tol = std::tan(p.merge_max_angle_deg * CV_PI / 180.0);
  const bool slopes_reliable = up.height > 40 && down.height > 40;
  if (slopes_reliable &&
      (std::abs(up.left.a - down.left.a) > tol || std::abs(up.right.a - down.right.a) > tol)) {
    return false;
  }
  return true;
}

/// Sub-pixel position of an edge along a scan line from |gradient| at i-1, i, i+1.
double parabola_offset(double gm, double g0, double gp) {
  const double den = gm - 2 * g0 + gp;
  return std::abs(den) > 1e-6 ? std::clamp(0.5 * (gm - gp) / den, -0.5, 0.5) : 0.0;
}

struct RefineImages {
  cv::Mat edges, gx, gy;  // full image, computed on demand inside ROIs
};

/// Outer edge of a side: for rows in [ya, yb] the outermost Canny edge within
/// the band [x(y) - 2, x(y) + dir * band]; returns x(y) fitted through them.
Line refine_side(const cv::Mat& gray, const Line& side, double ya, double yb, int dir, const BookDetectionParams& p,
                 int* support) {
  *support = 0;
  const int band = static_cast<int>(std::ceil(p.refine_band_px));
  const int y_lo = std::max(1, static_cast<int>(std::ceil(ya))), y_hi = std::min(gray.rows - 2, static_cast<int>(yb));
  if (y_hi - y_lo < 4) return Line{};
  const double xa = side.at(y_lo), xb = side.at(y_hi);
  const int x_lo = std::max(1, static_cast<int>(std::floor(std::min(xa, xb))) - band - 6);
  const int x_hi = std::min(gray.cols - 2, static_cast<int>(std::ceil(std::max(xa, xb))) + band + 6);
  if (x_hi - x_lo < 4) return Line{};
  const cv::Rect roi(x_lo - 1, y_lo - 1, x_hi - x_lo + 3, y_hi - y_lo + 3);
  const cv::Rect outer = cv::Rect(roi.x - 4, roi.y - 4, roi.width + 8, roi.height + 8) & cv::Rect(0, 0, gray.cols, gray.rows);
  cv::Mat blurred;
  if (p.refine_sigma_px > 0) {
    cv::GaussianBlur(gray(outer), blurred, cv::Size(0, 0), p.refine_sigma_px);
  } else {
    blurred = gray(outer).clone();
  }
  const cv::Mat patch = blurred(cv::Rect(roi.x - outer.x, roi.y - outer.y, roi.width, roi.height));
  cv::Mat edges, gx, gy;
  cv::Canny(patch, edges, p.refine_canny_low, p.refine_canny_high, 3, true);
  cv::Sobel(patch, gx, CV_32F, 1, 0, 3);
  cv::Sobel(patch, gy, CV_32F, 0, 1, 3);
  std::vector<cv::Point2d> pts;
  for (int y = y_lo; y <= y_hi; ++y) {
    const int ry = y - roi.y;
    const double xp = side.at(y);
    const int from = static_cast<int>(std::lround(xp)) - dir * 2;
    const int to = static_cast<int>(std::lround(xp)) + dir * band;
    int found = -1;
    for (int x = from; dir > 0 ? x <= to : x >= to; x += dir) {
      const int rx = x - roi.x;
      if (rx < 1 || rx >= roi.width - 1) continue;
      if (!edges.at<uint8_t>(ry, rx)) continue;
      if (std::abs(gx.at<float>(ry, rx)) <= std::abs(gy.at<float>(ry, rx))) continue;
      found = rx;  // keep the outermost
    }
    if (found < 0) continue;
    const double off = parabola_offset(std::abs(gx.at<float>(ry, found - 1)), std::abs(gx.at<float>(ry, found)),
                                       std::abs(gx.at<float>(ry, found + 1)));
    pts.emplace_back(y, roi.x + found + off);
  }
  *support = static_cast<int>(pts.size());
  if (pts.size() < 5) return Line{};
  return robust_fit(pts, 1.0);
}

/// Outer upper edge: for columns in [xa, xb] the upper-most Canny edge within
/// [y(x) - band, y(x) + 2]; returns y(x) fitted through them.
Line refine_top(const cv::Mat& gray, const Line& top, double xa, double xb, const BookDetectionParams& p,
                int* support) {
  *support = 0;
  const int band = static_cast<int>(std::ceil(p.refine_band_px));
  const int x_lo = std::max(1, static_cast<int>(std::ceil(xa))), x_hi = std::min(gray.cols - 2, static_cast<int>(xb));
  if (x_hi - x_lo < 4) return Line{};
  const double ya = top.at(x_lo), yb = top.at(x_hi);
  const int y_lo = std::max(1, static_cast<int>(std::floor(std::min(ya, yb))) - band - 6);
  const int y_hi = std::min(gray.rows - 2, static_cast<int>(std::ceil(std::max(ya, yb))) + 8);
  if (y_hi - y_lo < 4) return Line{};
  const cv::Rect roi(x_lo - 1, y_lo - 1, x_hi - x_lo + 3, y_hi - y_lo + 3);
  const cv::Rect outer = cv::Rect(roi.x - 4, roi.y - 4, roi.width + 8, roi.height + 8) & cv::Rect(0, 0, gray.cols, gray.rows);
  cv::Mat blurred;
  if (p.refine_sigma_px > 0) {
    cv::GaussianBlur(gray(outer), blurred, cv::Size(0, 0), p.refine_sigma_px);
  } else {
    blurred = gray(outer).clone();
  }
  const cv::Mat patch = blurred(cv::Rect(roi.x - outer.x, roi.y - outer.y, roi.width, roi.height));
  cv::Mat edges, gx, gy;
  cv::Canny(patch, edges, p.refine_canny_low, p.refine_canny_high, 3, true);
  cv::Sobel(patch, gx, CV_32F, 1, 0, 3);
  cv::Sobel(patch, gy, CV_32F, 0, 1, 3);
  std::vector<cv::Point2d> pts;
  for (int x = x_lo; x <= x_hi; ++x) {
    const int rx = x - roi.x;
    const double yp = top.at(x);
    const int from = static_cast<int>(std::lround(yp)) + 2, to = static_cast<int>(std::lround(yp)) - band;
    int found = -1;
    for (int y = from; y >= to; --y) {
      const int ry = y - roi.y;
      if (ry < 1 || ry >= roi.height - 1) continue;
      if (!edges.at<uint8_t>(ry, rx)) continue;
      if (std::abs(gy.at<float>(ry, rx)) <= std::abs(gx.at<float>(ry, rx))) continue;
      found = ry;  // keep the upper-most
    }
    if (found < 0) continue;
    const double off = parabola_offset(std::abs(gy.at<float>(found - 1, rx)), std::abs(gy.at<float>(found, rx)),
                                       std::abs(gy.at<float>(found + 1, rx)));
    pts.emplace_back(x, roi.y + found + off);
  }
  *support = static_cast<int>(pts.size());
  if (pts.size() < 4) return Line{};
  return robust_fit(pts, 1.0);
}

/// Intersection of x = side(y) and y = top(x).
cv::Point2d intersect(const Line& side, const Line& top) {
  // y = ta * (sa * y + sb) + tb
  const double y = (top.a * side.b + top.b) / (1.0 - top.a * side.a);
  return {side.at(y), y};
}

}  // namespace

BookDetection detect_books_hand(const cv::Mat& image, const BookDetectionParams& p) {
  if (image.empty()) throw std::invalid_argument("detect_books_hand: empty image");
  if (image.type() != CV_8UC3 && image.type() != CV_8UC1) {
    throw std::invalid_argument("detect_books_hand: image must be CV_8UC3 (RGB) or CV_8UC1");
  }
  BookDetection out;
  cv::Mat gray;
  if (image.channels() == 3) {
    cv::cvtColor(image, gray, cv::COLOR_RGB2GRAY);
  } else {
    gray = image;
  }
  if (p.use_stripe) out.stripe = detect_stripe(image, p.stripe);

  // Illumination normalisation: divide by the large-scale background (light).
  const int s = std::max(1, p.illumination_scale);
  cv::Mat small, light;
  cv::resize(gray, small, cv::Size(std::max(1, gray.cols / s), std::max(1, gray.rows / s)), 0, 0, cv::INTER_AREA);
  cv::GaussianBlur(small, small, cv::Size(0, 0), std::max(0.5, p.illumination_sigma_px / s));
  cv::resize(small, light, gray.size(), 0, 0, cv::INTER_LINEAR);
  cv::Mat norm;
  cv::divide(gray, cv::max(light, 1), norm, 128.0, CV_8U);
  if (p.blur_sigma_px > 0) cv::GaussianBlur(norm, norm, cv::Size(0, 0), p.blur_sigma_px);

  cv::Mat edges;
  cv::Canny(norm, edges, p.canny_low, p.canny_high, 3, true);
  if (p.edge_dilate_px > 0) {
    const int k = 2 * p.edge_dilate_px + 1;
    cv::dilate(edges, edges, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(k, k)));
  }
  cv::Mat regions = edges == 0;
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(regions, labels, stats, centroids, 4, CV_32S);

  // Pieces: regions big enough, with their outline per row and per column.
  std::vector<Piece> pieces;
  for (int i = 1; i < n; ++i) {
    const int area = stats.at<int>(i, cv::CC_STAT_AREA);
    const int bw = stats.at<int>(i, cv::CC_STAT_WIDTH), bh = stats.at<int>(i, cv::CC_STAT_HEIGHT);
    if (area < p.min_piece_area_px || bw < 0.5 * p.min_width_px) continue;
    Piece pc;
    pc.x0 = stats.at<int>(i, cv::CC_STAT_LEFT);
    pc.y0 = stats.at<int>(i, cv::CC_STAT_TOP);
    pc.area = area;
    pc.xmin.assign(static_cast<size_t>(bh), -1);
    pc.xmax.assign(static_cast<size_t>(bh), -1);
    pc.ymin.assign(static_cast<size_t>(bw), -1);
    pc.ymax.assign(static_cast<size_t>(bw), -1);
    for (int y = pc.y0; y < pc.y0 + bh; ++y) {
      const int* row = labels.ptr<int>(y);
      for (int x = pc.x0; x < pc.x0 + bw; ++x) {
        if (row[x] != i) continue;
        const size_t r = static_cast<size_t>(y - pc.y0), c = static_cast<size_t>(x - pc.x0);
        if (pc.xmin[r] < 0) pc.xmin[r] = x;
        pc.xmax[r] = x;
        if (pc.ymin[c] < 0) pc.ymin[c] = y;
        pc.ymax[c] = y;
      }
    }
    fit_piece(pc);
    pieces.push_back(std::move(pc));
  }

  // Merge pieces of one book (split by shadows, stamps, print) until nothing changes.
  bool merged = true;
  while (merged) {
    merged = false;
    for (size_t i = 0; i < pieces.size() && !merged; ++i) {
      if (!pieces[i].alive) continue;
      for (size_t j = 0; j < pieces.size() && !merged; ++j) {
        if (i == j || !pieces[j].alive) continue;
        if (pieces[i].top_y < pieces[j].top_y && same_book(pieces[i], pieces[j], p)) {
          absorb(pieces[i], pieces[j]);
          merged = true;
        }
      }
    }
  }

  const double max_lean = std::tan(p.max_lean_deg * CV_PI / 180.0);
  for (const Piece& pc : pieces) {
    if (!pc.alive) continue;
    BookCandidate c;
    c.id = static_cast<int>(out.candidates.size());
    c.bbox = cv::Rect(pc.x0, pc.y0, pc.x1() - pc.x0 + 1, pc.y1() - pc.y0 + 1);
    c.num_merged = pc.num_merged;
    c.width_px = pc.width;
    c.height_px = pc.height;
    c.fill_ratio = pc.area / std::max(1.0, pc.width * pc.height);
    if (pc.left.ok && pc.right.ok && pc.top.ok) {
      c.corner_r = intersect(pc.right, pc.top);
      c.corner_l = intersect(pc.left, pc.top);
      c.slope_rad = std::atan(pc.top.a);
    }
    auto reject = [&](const std::string& why) {
      if (c.reject_reason.empty()) c.reject_reason = why;
    };
    if (!pc.left.ok || !pc.right.ok || !pc.top.ok) reject("outline too small to fit its edges");
    if (pc.width < p.min_width_px) reject("narrower than min_width_px (cover strip, gap or print)");
    if (pc.width > p.max_width_px) reject("wider than max_width_px (background or several books)");
    if (pc.height < p.min_height_px) reject("lower than min_height_px");
    if (c.fill_ratio < p.min_fill_ratio) reject("not a quadrilateral (fill ratio below min_fill_ratio)");
    if (std::abs(pc.right.a) > max_lean || std::abs(pc.left.a) > max_lean) reject("sides lean more than max_lean_deg");
    if (c.bbox.y <= p.border_margin_px) reject("upper edge cut by the image border");
    if (c.bbox.x + c.bbox.width - 1 >= gray.cols - 1 - p.border_margin_px) reject("right edge cut by the image border");
    if (p.use_stripe && out.stripe.found && pc.bottom_y < out.stripe.centre_y_at(pc.centre_x)) {
      reject("lies above the black stripe (rear board)");
    }
    c.accepted = c.reject_reason.empty();
    if (c.accepted) {
      // Corners on the outer (cover) edges, sub-pixel.
      const double y_top_r = pc.top.at(pc.right.at(pc.top_y));
      const double span = std::min(pc.height, 150.0);
      int sr = 0, sl = 0, st = 0;
      const Line right = refine_side(gray, pc.right, y_top_r + 4, y_top_r + span, +1, p, &sr);
      const double y_top_l = pc.top.at(pc.left.at(pc.top_y));
      const Line left = refine_side(gray, pc.left, y_top_l + 4, y_top_l + span, -1, p, &sl);
      const Line r_side = right.ok ? right : pc.right;
      const Line l_side = left.ok ? left : pc.left;
      const double xl = l_side.at(pc.top_y), xr = r_side.at(pc.top_y);
      const double inset = 0.15 * (xr - xl);
      const Line top = refine_top(gray, pc.top, xl + inset, xr - inset, p, &st);
      const Line t_line = top.ok ? top : pc.top;
      c.corner_r = intersect(r_side, t_line);
      c.corner_l = intersect(l_side, t_line);
      c.refined = right.ok && top.ok;
      // Slope: upper edge and (perpendicular) right side, weighted by their lengths.
      const double side_len = std::min(pc.height, 150.0), top_len = xr - xl;
      const double from_top = std::atan(t_line.a), from_side = -std::atan(r_side.a);
      c.slope_rad = (from_top * top_len + from_side * side_len) / (top_len + side_len);
      const double yr = c.corner_r.y + 10;
      c.width_px = (r_side.at(yr) - l_side.at(yr)) * std::cos(c.slope_rad);
    }
    out.candidates.push_back(c);
  }
  for (const BookCandidate& c : out.candidates)
    if (c.accepted) out.ranking.push_back(c.id);
  std::sort(out.ranking.begin(), out.ranking.end(), [&](int a, int b) {
    return out.candidates[static_cast<size_t>(a)].corner_r.x > out.candidates[static_cast<size_t>(b)].corner_r.x;
  });
  out.found = !out.ranking.empty();
  if (!out.found) {
    out.failure_reason = out.candidates.empty() ? "no closed region of book size in the edge image"
                                                : "no candidate passed the book criteria (see candidates)";
  }
  return out;
}

}  // namespace bookgrasp
