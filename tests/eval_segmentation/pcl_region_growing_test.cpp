// Region growing on normals on an analytic organized cloud: a roof of two planes meeting at a crease
// (77 deg between the normals, no depth jump), checked by Hoover's metric against the analytic labels.
#include "services/eval_segmentation/pcl_region_growing.h"

#include <cmath>
#include <stdexcept>

#include <gtest/gtest.h>

#include "services/eval_segmentation/hoover_comparison.h"

namespace bookgrasp::eval_segmentation {
namespace {

// 160 x 120 pinhole (f = 150 px, centre 80, 60). Left of column 80: plane z = 2 + 0.8 x; right: z = 2 - 0.8 x
// (metres, camera frame): on the ray x = a z these give z = 2 / (1 - 0.8 a) and 2 / (1 + 0.8 a). Rows 0-19 are
// invalid (NaN). Ground truth: 1 left, 2 right, 0 on the invalid rows.
void roof(cv::Mat* points, cv::Mat* gt) {
  *points = cv::Mat(120, 160, CV_32FC3);
  *gt = cv::Mat(120, 160, CV_32S, cv::Scalar(0));
  for (int v = 0; v < 120; ++v)
    for (int u = 0; u < 160; ++u) {
      const double a = (u - 80) / 150.0, b = (v - 60) / 150.0;
      const bool left = u < 80;
      const double z = left ? 2.0 / (1.0 - 0.8 * a) : 2.0 / (1.0 + 0.8 * a);
      if (v < 20) {
        points->at<cv::Vec3f>(v, u) = cv::Vec3f(NAN, NAN, NAN);
        continue;
      }
      points->at<cv::Vec3f>(v, u) = cv::Vec3f(float(a * z), float(b * z), float(z));
      gt->at<int>(v, u) = left ? 1 : 2;
    }
}

TEST(RegionGrowing, SeparatesTwoPlanesAtACrease) {
  cv::Mat points, gt;
  roof(&points, &gt);
  RegionGrowingParams p;
  p.normal_smoothing_size = 5.0;
  const cv::Mat labels = segment_region_growing(points, p);
  ASSERT_EQ(labels.type(), CV_32S);
  // No label on invalid points.
  EXPECT_EQ(cv::countNonZero(labels(cv::Rect(0, 0, 160, 20))), 0);
  const HooverResult r = hoover_compare(gt, labels, 0.8);
  EXPECT_EQ(r.correct, 2) << "over " << r.over << " under " << r.under << " missed " << r.missed;
}

TEST(RegionGrowing, EmptyOfValidPointsGivesNoRegion) {
  const cv::Mat nan(10, 10, CV_32FC3, cv::Scalar(NAN, NAN, NAN));
  EXPECT_EQ(cv::countNonZero(segment_region_growing(nan, RegionGrowingParams())), 0);
}

TEST(RegionGrowing, BadInputIsRefused) {
  EXPECT_THROW(segment_region_growing(cv::Mat(), RegionGrowingParams()), std::invalid_argument);
  EXPECT_THROW(segment_region_growing(cv::Mat(4, 4, CV_32F), RegionGrowingParams()), std::invalid_argument);
  RegionGrowingParams p;
  p.neighbours = 1;
  EXPECT_THROW(segment_region_growing(cv::Mat(4, 4, CV_32FC3, cv::Scalar(0, 0, 1)), p), std::invalid_argument);
}

}  // namespace
}  // namespace bookgrasp::eval_segmentation
