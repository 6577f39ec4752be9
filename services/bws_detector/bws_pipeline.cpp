#include "services/bws_detector/bws_pipeline.h"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "common/config.h"

namespace bookgrasp::bws {

BwsParams BwsParams::from_config(const Config& root) {
  BwsParams p;
  p.implementation = root.get_choice("service.implementation", {kImplGod, kImplPcl});
  p.disparity = DisparityParams::from_config(root.child("disparity"));
  if (p.implementation == kImplGod)
    p.god = GodParams::from_config(root.child("god"));
  else
    p.pcl = PclPlaneParams::from_config(root.child("pcl"));
  p.selection = SelectionParams::from_config(root.child("selection"));
  p.cart = CartGeometry::from_config(root.child("cart"));
  return p;
}

SegmentationResult segment(const cv::Mat& disparity, const cv::Mat& points, const BwsParams& p) {
  if (p.implementation == kImplGod) return segment_god(disparity, points, p.god);
  if (p.implementation == kImplPcl) return segment_pcl_planes(disparity, points, p.pcl);
  throw std::invalid_argument("unknown segmentation implementation '" + p.implementation + "' (use god or pcl)");
}

BwsOutput run_bws(const StereoInput& in, const Eigen::Isometry3d& marker_in_base, const BwsParams& p,
                  bool measure_time) {
  using Clock = std::chrono::steady_clock;
  const auto ms = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double, std::milli>(b - a).count();
  };
  const StereoGeometry& g = in.geometry;
  if (!(std::isfinite(g.fx) && std::isfinite(g.fy) && std::isfinite(g.cx) && std::isfinite(g.cy) &&
        std::isfinite(g.baseline_m)) ||
      g.fx <= 0 || g.fy <= 0 || g.baseline_m <= 0)
    throw std::invalid_argument("stereo geometry must have finite fx, fy, cx, cy and positive fx, fy, baseline");
  if (!in.camera_in_base.matrix().allFinite() || !marker_in_base.matrix().allFinite())
    throw std::invalid_argument("camera or marker pose is not finite");

  BwsOutput out;
  const auto t0 = Clock::now();
  out.disparity = compute_disparity(in.left, in.right, p.disparity);
  out.points_camera = disparity_to_points(out.disparity, g);
  const auto t1 = Clock::now();
  out.num_valid_disparity = 0;
  for (int y = 0; y < out.disparity.rows; ++y) {
    const float* d = out.disparity.ptr<float>(y);
    for (int x = 0; x < out.disparity.cols; ++x) out.num_valid_disparity += (std::isfinite(d[x]) && d[x] > 0.f);
  }
  out.segmentation = segment(out.disparity, out.points_camera, p);
  const auto t2 = Clock::now();
  out.cart_in_base = cart_from_marker(marker_in_base, p.cart);
  out.shelf = shelf_volume(out.cart_in_base, p.cart);
  out.grasp_in_base = grasp_frame_of_cart(out.cart_in_base);
  out.selection = select_book_front(out.segmentation, out.points_camera, g, in.camera_in_base, out.shelf, p.selection);
  if (out.selection.found) out.p1_grasp = out.grasp_in_base.inverse() * out.selection.p1_base;
  const auto t3 = Clock::now();
  if (measure_time) {
    out.disparity_ms = ms(t0, t1);
    out.segmentation_ms = ms(t1, t2);
    out.total_ms = ms(t0, t3);
  }
  return out;
}

}  // namespace bookgrasp::bws
