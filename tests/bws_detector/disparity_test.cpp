// Disparity and 3D reconstruction: conventions on synthetic input, accuracy on the real Middlebury pairs.
#include "services/bws_detector/disparity.h"

#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

namespace bookgrasp::bws {
namespace {

const std::string kData = std::string(BOOKGRASP_SOURCE_DIR) + "/tests/data/middlebury/";

TEST(DisparityToPoints, PinholeGeometry) {
  cv::Mat d(4, 5, CV_32F, cv::Scalar(10.f));
  d.at<float>(1, 1) = std::nanf("");
  d.at<float>(2, 2) = 0.f;
  const StereoGeometry g{100.0, 120.0, 2.0, 1.5, 0.1};
  const cv::Mat p = disparity_to_points(d, g);
  // z = 100 * 0.1 / 10 = 1; x = (u - 2) / 100; y = (v - 1.5) / 120.
  const cv::Vec3f q = p.at<cv::Vec3f>(3, 4);
  EXPECT_FLOAT_EQ(q[2], 1.0f);
  EXPECT_FLOAT_EQ(q[0], 0.02f);
  EXPECT_FLOAT_EQ(q[1], 1.5f / 120.f);
  EXPECT_TRUE(std::isnan(p.at<cv::Vec3f>(1, 1)[2]));
  EXPECT_TRUE(std::isnan(p.at<cv::Vec3f>(2, 2)[2]));  // d <= 0: no point
  const cv::Mat z = disparity_to_depth(d, g);
  EXPECT_FLOAT_EQ(z.at<float>(0, 0), 1.0f);
  EXPECT_TRUE(std::isnan(z.at<float>(2, 2)));
  // Into base: a pure translation and a 90 deg yaw.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(1, 2, 3);
  const cv::Vec3f b = transform_points(p, T).at<cv::Vec3f>(3, 4);
  EXPECT_NEAR(b[0], 1.0 - q[1], 1e-6);
  EXPECT_NEAR(b[1], 2.0 + q[0], 1e-6);
  EXPECT_NEAR(b[2], 3.0 + q[2], 1e-6);
  EXPECT_TRUE(std::isnan(transform_points(p, T).at<cv::Vec3f>(1, 1)[0]));
}

TEST(ComputeDisparity, BadInputThrows) {
  DisparityParams p;
  EXPECT_THROW(compute_disparity(cv::Mat(), cv::Mat(), p), std::invalid_argument);
  EXPECT_THROW(compute_disparity(cv::Mat(10, 10, CV_8U), cv::Mat(10, 11, CV_8U), p), std::invalid_argument);
  EXPECT_THROW(compute_disparity(cv::Mat(10, 10, CV_32F), cv::Mat(10, 10, CV_32F), p), std::invalid_argument);
  p.num_disparities = 20;
  EXPECT_THROW(compute_disparity(cv::Mat(10, 10, CV_8U), cv::Mat(10, 10, CV_8U), p), std::invalid_argument);
  EXPECT_THROW(disparity_to_points(cv::Mat(3, 3, CV_32F), StereoGeometry{}), std::invalid_argument);
}

struct BadPixels {
  double coverage, bad1_valid, bad2_valid, bad1_all, bad2_all;
};

// Bad-pixel rates in non-occluded pixels with known ground truth (occl.png white, disp2 > 0).
// "_valid": among pixels with a disparity; "_all": a pixel without a disparity counts as bad.
BadPixels evaluate(const std::string& scene, const DisparityParams& p) {
  const cv::Mat left = cv::imread(kData + scene + "/im2.png", cv::IMREAD_COLOR);
  const cv::Mat right = cv::imread(kData + scene + "/im6.png", cv::IMREAD_COLOR);
  const cv::Mat gt = cv::imread(kData + scene + "/disp2.png", cv::IMREAD_GRAYSCALE);
  const cv::Mat occ = cv::imread(kData + scene + "/occl.png", cv::IMREAD_GRAYSCALE);
  EXPECT_FALSE(left.empty() || right.empty() || gt.empty() || occ.empty());
  const cv::Mat d = compute_disparity(left, right, p);
  int n = 0, valid = 0, b1 = 0, b2 = 0;
  for (int y = 0; y < d.rows; ++y)
    for (int x = 0; x < d.cols; ++x) {
      if (occ.at<uint8_t>(y, x) != 255 || gt.at<uint8_t>(y, x) == 0) continue;
      ++n;
      const float v = d.at<float>(y, x);
      if (!std::isfinite(v)) continue;
      ++valid;
      const double e = std::fabs(v - gt.at<uint8_t>(y, x) / 4.0);
      b1 += e > 1.0;
      b2 += e > 2.0;
    }
  BadPixels r{double(valid) / n, double(b1) / valid, double(b2) / valid, double(b1 + n - valid) / n,
              double(b2 + n - valid) / n};
  std::printf("%s %s: coverage %.3f, bad>1px %.3f / >2px %.3f of valid; counting holes as bad %.3f / %.3f\n",
              scene.c_str(), p.algorithm == StereoAlgorithm::kBlockMatching ? "StereoBM" : "StereoSGBM", r.coverage,
              r.bad1_valid, r.bad2_valid, r.bad1_all, r.bad2_all);
  return r;
}

// Measured (OpenCV 4.6, block 9): Teddy coverage 0.77, bad >1 px 6.0 %, >2 px 4.6 % of valid pixels;
// Cones 0.83, 2.7 %, 2.0 %. Thresholds leave about 2x headroom for OpenCV version changes.
TEST(ComputeDisparity, MiddleburyBadPixelRates) {
  DisparityParams bm;
  bm.block_size = 9;
  for (const char* scene : {"Teddy", "Cones"}) {
    const BadPixels r = evaluate(scene, bm);
    EXPECT_GT(r.coverage, 0.6) << scene;
    EXPECT_LT(r.bad2_valid, 0.10) << scene;
    EXPECT_LT(r.bad1_valid, 0.20) << scene;
  }
  DisparityParams sg = bm;
  sg.algorithm = StereoAlgorithm::kSemiGlobal;
  sg.block_size = 5;
  for (const char* scene : {"Teddy", "Cones"}) {
    const BadPixels r = evaluate(scene, sg);
    EXPECT_GT(r.coverage, 0.7) << scene;
    EXPECT_LT(r.bad2_valid, 0.10) << scene;
  }
}

}  // namespace
}  // namespace bookgrasp::bws
