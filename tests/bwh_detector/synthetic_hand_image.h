#pragma once
/// @file
/// Test helper: synthetic hand-camera images of a book shelf seen from the
/// front (page edges towards the camera) with known true geometry: books as
/// quadrilaterals side by side with page-edge line texture and coloured cover
/// strips, the black stripe on the rear board behind them, cast shadows
/// across the page edges, library stamps, uneven light and sensor noise.
/// Drawn at 4x and area-averaged, so edges are anti-aliased like a camera's.

#include <array>
#include <cmath>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace bookgrasp::test {

/// One book standing on the shelf (below the image), seen from its fore-edge.
struct SynthBook {
  double width_px = 60;        ///< thickness of the book in the image (outer cover to outer cover)
  double height_px = 400;      ///< along its axis from the shelf floor
  double lean_deg = 0;         ///< positive: top leans to the right (image)
  double cover_px = 4;         ///< visible cover board strip on each side
  cv::Scalar cover{40, 60, 150};  ///< cover colour (RGB)
  cv::Scalar pages{232, 224, 205};  ///< page-edge colour (RGB)
  double gap_before_px = 1;    ///< dark gap to the previous book
};

/// A library stamp on the page edge of book `book`.
struct SynthStamp {
  int book = 0;                ///< index into books
  double along = 0.5;          ///< position along the book axis, 0 = floor .. 1 = top
  double across = 0.5;         ///< position across the book, 0 = left .. 1 = right
  double radius_px = 18;       ///< stamp radius
  cv::Scalar colour{110, 40, 150};
};

/// A cast shadow: a polygon (image px) darkened by `factor` with a soft edge.
struct SynthShadow {
  std::vector<cv::Point2d> polygon;
  double factor = 0.55;
  double penumbra_px = 1.5;
};

/// The whole scene; books are placed left to right from first_book_x.
struct SynthScene {
  int width = 640, height = 480;
  cv::Scalar board{176, 150, 112};      ///< rear board colour (RGB)
  double floor_y = 560;                 ///< shelf floor (image y), below the image
  double first_book_x = 40;             ///< x of the first book's lower-left corner on the floor
  std::vector<SynthBook> books;
  bool stripe = true;
  double stripe_y = 300;                ///< stripe centre line y at x = 0
  double stripe_angle_deg = 0;          ///< positive: descends to the right
  double stripe_thickness_px = 20;
  cv::Scalar stripe_colour{22, 22, 24};
  std::vector<SynthStamp> stamps;
  std::vector<SynthShadow> shadows;
  double light_gradient = 0.0;          ///< brightness falls by this fraction from left to right
  double noise_sigma = 2.0;
  uint64_t seed = 1;
};

/// What is true about a drawn scene (image px, pixel centres at integers).
struct SynthTruth {
  std::vector<std::array<cv::Point2d, 4>> quads;  ///< per book: bottom-left, bottom-right, top-right, top-left
  cv::Point2d r;                                  ///< upper-right corner of the right-most book
  double slope_rad = 0;                           ///< slope of its upper edge
  double width_px = 0;                            ///< its thickness (perpendicular)
  bool stripe_end_visible = false;                ///< the right-most book hides the stripe inside the image
  cv::Point2d stripe_end;                         ///< stripe centre line meets its right edge
};

inline std::array<cv::Point2d, 4> book_quad(cv::Point2d bl, const SynthBook& b) {
  const double t = b.lean_deg * CV_PI / 180.0;
  const cv::Point2d across(std::cos(t), std::sin(t)), up(std::sin(t), -std::cos(t));
  const cv::Point2d br = bl + b.width_px * across;
  return {bl, br, br + b.height_px * up, bl + b.height_px * up};
}

/// Draws the scene into an RGB image and returns the truth.
inline cv::Mat render_scene(const SynthScene& s, SynthTruth* truth) {
  const int ss = 4;
  auto to_big = [&](cv::Point2d p) {
    // 4x image with 4 more bits of sub-pixel precision (shift = 2 -> x4).
    return cv::Point(static_cast<int>(std::lround((p.x * ss + (ss - 1) / 2.0) * 4)),
                     static_cast<int>(std::lround((p.y * ss + (ss - 1) / 2.0) * 4)));
  };
  auto poly = [&](cv::Mat& img, const std::vector<cv::Point2d>& pts, const cv::Scalar& c) {
    std::vector<cv::Point> q;
    for (const auto& p : pts) q.push_back(to_big(p));
    cv::fillConvexPoly(img, q, c, cv::LINE_8, 2);
  };
  cv::RNG rng(s.seed);
  cv::Mat big(s.height * ss, s.width * ss, CV_8UC3, s.board);
  // Board grain: faint horizontal streaks.
  for (int y = 0; y < big.rows; y += 6) {
    const double f = 1.0 + rng.uniform(-0.03, 0.03);
    cv::Mat row = big.rowRange(y, std::min(big.rows, y + 6));
    row.convertTo(row, -1, f, 0);
  }
  if (s.stripe) {
    const double t = std::tan(s.stripe_angle_deg * CV_PI / 180.0);
    const double h = s.stripe_thickness_px / 2.0 / std::cos(std::atan(t));
    const double x1 = s.width + 10;
    poly(big, {{-10, s.stripe_y - 10 * t - h}, {x1, s.stripe_y + x1 * t - h}, {x1, s.stripe_y + x1 * t + h},
               {-10, s.stripe_y - 10 * t + h}},
         s.stripe_colour);
  }
  truth->quads.clear();
  cv::Point2d bl(s.first_book_x, s.floor_y);
  for (size_t i = 0; i < s.books.size(); ++i) {
    const SynthBook& b = s.books[i];
    const double t = b.lean_deg * CV_PI / 180.0;
    const cv::Point2d across(std::cos(t), std::sin(t)), up(std::sin(t), -std::cos(t));
    bl += b.gap_before_px * across;
    const auto q = book_quad(bl, b);
    truth->quads.push_back(q);
    // Dark gap (shadow between books) just before the book.
    if (b.gap_before_px > 0) {
      poly(big, {q[0] - b.gap_before_px * across, q[0], q[3], q[3] - b.gap_before_px * across},
           cv::Scalar(35, 30, 28));
    }
    poly(big, {q[0], q[1], q[2], q[3]}, b.cover);
    const cv::Point2d c = b.cover_px * across;
    const std::vector<cv::Point2d> pages{q[0] + c, q[1] - c, q[2] - c, q[3] + c};
    poly(big, pages, b.pages);
    // Page-edge texture: fine lines along the book axis.
    for (double off = b.cover_px + 1.0; off < b.width_px - b.cover_px - 0.5; off += rng.uniform(1.2, 3.0)) {
      const double f = rng.uniform(0.86, 0.97);
      const cv::Scalar col(b.pages[0] * f, b.pages[1] * f, b.pages[2] * f);
      const cv::Point2d a = q[0] + off * across, e = q[3] + off * across + 0.6 * up * 0.0;
      cv::line(big, to_big(a), to_big(e), col, 2, cv::LINE_8, 2);
    }
    bl = q[1];
  }
  for (const SynthStamp& st : s.stamps) {
    const auto& q = truth->quads[static_cast<size_t>(st.book)];
    const cv::Point2d bottom = q[0] + st.across * (q[1] - q[0]);
    const cv::Point2d top = q[3] + st.across * (q[2] - q[3]);
    const cv::Point2d c = bottom + st.along * (top - bottom);
    const cv::Point cb = to_big(c);
    const int r = static_cast<int>(st.radius_px * ss * 4);
    cv::circle(big, cb, r, st.colour, static_cast<int>(ss * 3), cv::LINE_8, 2);
    cv::circle(big, cb, r * 6 / 10, st.colour, cv::FILLED, cv::LINE_8, 2);
    cv::line(big, cb - cv::Point(r * 4 / 10, 0), cb + cv::Point(r * 4 / 10, 0), cv::Scalar(240, 235, 220),
             ss * 2, cv::LINE_8, 2);
  }
  cv::Mat img;
  cv::resize(big, img, cv::Size(s.width, s.height), 0, 0, cv::INTER_AREA);

  // Light: gradient and cast shadows, multiplicative.
  cv::Mat light(img.size(), CV_32FC1);
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x)
      light.at<float>(y, x) = static_cast<float>(1.0 - s.light_gradient * x / img.cols);
  for (const SynthShadow& sh : s.shadows) {
    cv::Mat m(img.rows * ss, img.cols * ss, CV_8UC1, cv::Scalar(0));
    std::vector<cv::Point> q;
    for (const auto& p : sh.polygon) q.push_back(to_big(p));
    cv::fillPoly(m, std::vector<std::vector<cv::Point>>{q}, cv::Scalar(255), cv::LINE_8, 2);
    cv::Mat mf;
    cv::resize(m, mf, img.size(), 0, 0, cv::INTER_AREA);
    mf.convertTo(mf, CV_32F, 1.0 / 255);
    if (sh.penumbra_px > 0) cv::GaussianBlur(mf, mf, cv::Size(0, 0), sh.penumbra_px);
    light = light.mul(1.0 - (1.0 - sh.factor) * mf);
  }
  cv::Mat f;
  img.convertTo(f, CV_32FC3);
  std::vector<cv::Mat> ch;
  cv::split(f, ch);
  for (auto& c : ch) {
    c = c.mul(light);
    cv::Mat noise(c.size(), CV_32FC1);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, s.noise_sigma);
    c += noise;
  }
  cv::merge(ch, f);
  f.convertTo(img, CV_8UC3);

  const auto& last = truth->quads.back();
  const SynthBook& lb = s.books.back();
  truth->r = last[2];
  truth->slope_rad = std::atan2(last[2].y - last[3].y, last[2].x - last[3].x);
  truth->width_px = lb.width_px;
  // Stripe centre line y = stripe_y + x tan(a) meets the right edge q1 -> q2.
  const double t = std::tan(s.stripe_angle_deg * CV_PI / 180.0);
  const cv::Point2d d = last[2] - last[1];
  // Solve q1 + u d on the line: q1.y + u d.y = stripe_y + (q1.x + u d.x) t.
  const double u = (s.stripe_y + last[1].x * t - last[1].y) / (d.y - d.x * t);
  truth->stripe_end = last[1] + u * d;
  const double stripe_top_at_edge = truth->stripe_end.y - s.stripe_thickness_px;
  truth->stripe_end_visible = s.stripe && u > 0 && u < 1 && last[2].y < stripe_top_at_edge &&
                              truth->stripe_end.x > 0 && truth->stripe_end.x < s.width - 1;
  return img;
}

/// A scene like the hand camera sees near P1: five books, the right-most
/// ending near the image centre, the stripe visible to its right.
inline SynthScene default_scene() {
  SynthScene s;
  const cv::Scalar covers[] = {{150, 30, 35}, {30, 60, 140}, {40, 110, 60}, {120, 90, 40}, {90, 30, 100},
                               {200, 170, 40}};
  const double widths[] = {70, 45, 95, 60, 80};
  const double heights[] = {430, 360, 440, 390, 420};
  for (int i = 0; i < 5; ++i) {
    SynthBook b;
    b.width_px = widths[i];
    b.height_px = heights[i];
    b.lean_deg = 1.5;
    b.cover = covers[i];
    b.gap_before_px = i == 0 ? 0 : 1.0;
    s.books.push_back(b);
  }
  s.first_book_x = -20;
  return s;
}

}  // namespace bookgrasp::test
