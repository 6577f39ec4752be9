#include "services/bws_detector/disparity.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "common/config.h"

namespace bookgrasp::bws {

DisparityParams DisparityParams::from_config(const Config& c) {
  DisparityParams p;
  p.algorithm = c.get_choice("algorithm", {"bm", "sgbm"}) == "bm" ? StereoAlgorithm::kBlockMatching
                                                                  : StereoAlgorithm::kSemiGlobal;
  p.min_disparity = c.get_int("min_disparity", -1024, 1024);
  p.num_disparities = c.get_int("num_disparities", 16, 1024);
  p.block_size = c.get_int("block_size", 1, 255);
  p.pre_filter_cap = c.get_int("pre_filter_cap", 1, 63);
  p.texture_threshold = c.get_int("texture_threshold", 0, 100000);
  p.uniqueness_ratio = c.get_int("uniqueness_ratio", 0, 100);
  p.speckle_window_size = c.get_int("speckle_window_size", 0, 100000);
  p.speckle_range = c.get_int("speckle_range", 0, 1000);
  p.disp12_max_diff = c.get_int("disp12_max_diff", -1, 1000);
  p.sgbm_p1_factor = c.get_int("sgbm_p1_factor", 0, 1000);
  p.sgbm_p2_factor = c.get_int("sgbm_p2_factor", 0, 1000);
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    throw ConfigError(c.source() + ": section " + c.path_of("block_size") + ": " + e.what());
  }
  return p;
}

void DisparityParams::validate() const {
  if (num_disparities <= 0 || num_disparities % 16 != 0)
    throw std::invalid_argument("num_disparities must be a positive multiple of 16");
  if (block_size % 2 == 0) throw std::invalid_argument("block_size must be odd");
  if (algorithm == StereoAlgorithm::kBlockMatching && (block_size < 5 || block_size > 255))
    throw std::invalid_argument("block_size must be in [5, 255] for StereoBM");
  if (sgbm_p2_factor <= sgbm_p1_factor && algorithm == StereoAlgorithm::kSemiGlobal)
    throw std::invalid_argument("sgbm_p2_factor must be > sgbm_p1_factor");
}

namespace {

/// What compute_disparity and disparity_to_points keep across frames (one set per thread), so that a
/// frame of the usual size reuses the previous frame's memory instead of faulting in fresh pages: the
/// StereoBM matcher (its internal buffers; every parameter is set on each call), the grey and raw
/// images, and the returned images, which are reused only once the caller no longer holds them.
struct DisparityWorkspace {
  cv::Ptr<cv::StereoBM> bm;
  cv::Mat grey_left, grey_right, raw, disparity, points;
  std::vector<double> column_x;  // (x - cx) / fx of every column
};

DisparityWorkspace& workspace() {
  thread_local DisparityWorkspace ws;
  return ws;
}

/// A workspace image for this call: dropped first if the caller still holds it (a returned image).
cv::Mat& own(cv::Mat& m) {
  if (m.u && m.u->refcount > 1) m.release();
  return m;
}

}  // namespace

cv::Mat compute_disparity(const cv::Mat& left, const cv::Mat& right, const DisparityParams& p) {
  p.validate();
  if (left.empty() || right.empty()) throw std::invalid_argument("compute_disparity: empty image");
  if (left.size() != right.size() || left.type() != right.type())
    throw std::invalid_argument("compute_disparity: left and right differ in size or type");
  DisparityWorkspace& ws = workspace();
  cv::Mat gl, gr;
  if (left.type() == CV_8UC3) {
    cv::cvtColor(left, own(ws.grey_left), cv::COLOR_BGR2GRAY);
    cv::cvtColor(right, own(ws.grey_right), cv::COLOR_BGR2GRAY);
    gl = ws.grey_left;
    gr = ws.grey_right;
  } else if (left.type() == CV_8UC1) {
    gl = left;
    gr = right;
  } else {
    throw std::invalid_argument("compute_disparity: images must be CV_8UC1 or CV_8UC3");
  }
  cv::Mat& raw = own(ws.raw);
  if (p.algorithm == StereoAlgorithm::kBlockMatching) {
    if (!ws.bm) ws.bm = cv::StereoBM::create(p.num_disparities, p.block_size);
    cv::StereoBM& bm = *ws.bm;
    bm.setNumDisparities(p.num_disparities);
    bm.setBlockSize(p.block_size);
    bm.setMinDisparity(p.min_disparity);
    bm.setPreFilterCap(p.pre_filter_cap);
    bm.setTextureThreshold(p.texture_threshold);
    bm.setUniquenessRatio(p.uniqueness_ratio);
    bm.setSpeckleWindowSize(p.speckle_window_size);
    bm.setSpeckleRange(p.speckle_range * 16);
    bm.setDisp12MaxDiff(p.disp12_max_diff);
    bm.compute(gl, gr, raw);
  } else {
    const int area = p.block_size * p.block_size;
    auto sg = cv::StereoSGBM::create(p.min_disparity, p.num_disparities, p.block_size, p.sgbm_p1_factor * area,
                                     p.sgbm_p2_factor * area, p.disp12_max_diff, p.pre_filter_cap, p.uniqueness_ratio,
                                     p.speckle_window_size, p.speckle_range * 16, cv::StereoSGBM::MODE_SGBM_3WAY);
    sg->compute(gl, gr, raw);
  }
  // raw: CV_16S, 4 fractional bits; invalid = (min_disparity - 1) * 16.
  const int16_t invalid = int16_t((p.min_disparity - 1) * 16);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  cv::Mat& disp = own(ws.disparity);
  disp.create(raw.size(), CV_32F);
  for (int y = 0; y < raw.rows; ++y) {
    const int16_t* r = raw.ptr<int16_t>(y);
    float* d = disp.ptr<float>(y);
    for (int x = 0; x < raw.cols; ++x) d[x] = r[x] <= invalid ? nan : float(r[x]) * (1.f / 16.f);
  }
  return disp;
}

namespace {
void check(const cv::Mat& disparity, const StereoGeometry& g) {
  if (disparity.type() != CV_32F) throw std::invalid_argument("disparity must be CV_32F");
  if (!(g.fx > 0 && g.fy > 0 && g.baseline_m > 0))
    throw std::invalid_argument("stereo geometry needs fx, fy and baseline_m > 0");
}
}  // namespace

cv::Mat disparity_to_depth(const cv::Mat& disparity, const StereoGeometry& g) {
  check(disparity, g);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float fb = float(g.fx * g.baseline_m);
  cv::Mat z(disparity.size(), CV_32F);
  for (int y = 0; y < z.rows; ++y) {
    const float* d = disparity.ptr<float>(y);
    float* o = z.ptr<float>(y);
    for (int x = 0; x < z.cols; ++x) o[x] = (std::isfinite(d[x]) && d[x] > 0.f) ? fb / d[x] : nan;
  }
  return z;
}

cv::Mat disparity_to_points(const cv::Mat& disparity, const StereoGeometry& g) {
  check(disparity, g);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const double fb = g.fx * g.baseline_m;
  DisparityWorkspace& ws = workspace();
  cv::Mat& pts = own(ws.points);
  pts.create(disparity.size(), CV_32FC3);
  std::vector<double>& xn = ws.column_x;
  xn.resize(size_t(pts.cols));
  for (int x = 0; x < pts.cols; ++x) xn[size_t(x)] = (x - g.cx) / g.fx;
  for (int y = 0; y < pts.rows; ++y) {
    const float* d = disparity.ptr<float>(y);
    cv::Vec3f* o = pts.ptr<cv::Vec3f>(y);
    const double yn = (y - g.cy) / g.fy;
    for (int x = 0; x < pts.cols; ++x) {
      if (!(std::isfinite(d[x]) && d[x] > 0.f)) {
        o[x] = cv::Vec3f(nan, nan, nan);
        continue;
      }
      const double z = fb / d[x];
      o[x] = cv::Vec3f(float(xn[size_t(x)] * z), float(yn * z), float(z));
    }
  }
  return pts;
}

cv::Mat transform_points(const cv::Mat& points, const Eigen::Isometry3d& T) {
  if (points.type() != CV_32FC3) throw std::invalid_argument("transform_points: points must be CV_32FC3");
  const Eigen::Matrix3f R = T.linear().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  cv::Mat out(points.size(), CV_32FC3);
  for (int y = 0; y < points.rows; ++y) {
    const cv::Vec3f* p = points.ptr<cv::Vec3f>(y);
    cv::Vec3f* o = out.ptr<cv::Vec3f>(y);
    for (int x = 0; x < points.cols; ++x) {
      const Eigen::Vector3f q = R * Eigen::Vector3f(p[x][0], p[x][1], p[x][2]) + t;
      o[x] = cv::Vec3f(q.x(), q.y(), q.z());  // NaN propagates
    }
  }
  return out;
}

}  // namespace bookgrasp::bws
