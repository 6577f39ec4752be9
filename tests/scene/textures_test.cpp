// Tests of the scene textures (common/scene/textures.h).
#include "common/scene/textures.h"

#include <gtest/gtest.h>

extern "C" {
#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>
}
#include <opencv2/imgproc.hpp>

using namespace bookgrasp::scene;

TEST(Textures, AprilTagTextureDecodesAsItsId) {
  for (int id : {0, 1, 17, 586}) {
    const cv::Mat rgb = apriltag_texture(id, 12);
    ASSERT_EQ(rgb.cols, 120);
    cv::Mat grey, big;
    cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
    cv::copyMakeBorder(grey, big, 40, 40, 40, 40, cv::BORDER_CONSTANT, cv::Scalar(255));
    apriltag_family_t* tf = tag36h11_create();
    apriltag_detector_t* td = apriltag_detector_create();
    apriltag_detector_add_family(td, tf);
    image_u8_t im = {big.cols, big.rows, static_cast<int32_t>(big.step), big.data};
    zarray_t* dets = apriltag_detector_detect(td, &im);
    ASSERT_EQ(zarray_size(dets), 1) << "id " << id;
    apriltag_detection_t* det;
    zarray_get(dets, 0, &det);
    EXPECT_EQ(det->id, id);
    // Upright: the first corner (tag's bottom left) is at the image's bottom left.
    EXPECT_LT(det->p[0][0], big.cols / 2.0);
    EXPECT_GT(det->p[0][1], big.rows / 2.0);
    apriltag_detections_destroy(dets);
    apriltag_detector_destroy(td);
    tag36h11_destroy(tf);
  }
  EXPECT_THROW(apriltag_texture(587, 4), std::invalid_argument);
}

TEST(Textures, PageEdgeTextureIsOffWhiteWithLinesAndDeterministic) {
  Book b;
  b.width_m = 0.02;
  b.height_m = 0.25;
  b.page_rgb = {0.93, 0.91, 0.84};
  b.cover_rgb = {0.1, 0.2, 0.7};
  b.texture_seed = 99;
  RenderSettings r;
  const cv::Mat a = page_edge_texture(b, r), a2 = page_edge_texture(b, r);
  EXPECT_EQ(a.cols, 60);
  EXPECT_EQ(a.rows, 750);
  EXPECT_EQ(cv::norm(a, a2, cv::NORM_INF), 0.0);
  const cv::Vec3b mid = a.at<cv::Vec3b>(375, 30);
  EXPECT_GT(mid[0], 180);
  EXPECT_GT(mid[2], 160);
  // Columns differ (page lines) more than rows within a column.
  cv::Mat row = a.row(375).colRange(5, 55).clone(), col = a.col(30).rowRange(20, 730).clone();
  cv::Scalar m1, s1, m2, s2;
  cv::meanStdDev(row.reshape(1, 1), m1, s1);
  cv::meanStdDev(col.reshape(1, 1), m2, s2);
  EXPECT_GT(s1[0], s2[0]);
  // Cover colour at both sides.
  EXPECT_LT(a.at<cv::Vec3b>(375, 0)[0], 60);
  EXPECT_LT(a.at<cv::Vec3b>(375, 59)[0], 60);
}
