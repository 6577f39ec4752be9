#include "common/sim_render/sensor_model.h"

#include <gtest/gtest.h>

namespace bookgrasp::sim_render {
namespace {

TEST(SensorModel, NoiseHasTheConfiguredSpreadAndIsReproducible) {
  const cv::Mat grey(240, 320, CV_8UC3, cv::Scalar(128, 128, 128));
  SensorModel sensor;
  sensor.noise_stddev = 4.0;
  const cv::Mat a = apply_sensor_model(grey, sensor, frame_seed(7, 1000, "stereo_left"));
  const cv::Mat b = apply_sensor_model(grey, sensor, frame_seed(7, 1000, "stereo_left"));
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  cv::Scalar mean, stddev;
  cv::meanStdDev(a.reshape(1), mean, stddev);
  EXPECT_NEAR(mean[0], 128.0, 0.1);
  EXPECT_NEAR(stddev[0], 4.0, 0.1);  // rounding to integers adds 1/12 of variance
  // Another time, camera or scene seed gives other noise.
  EXPECT_GT(cv::norm(a, apply_sensor_model(grey, sensor, frame_seed(7, 2000, "stereo_left")), cv::NORM_L1), 0.0);
  EXPECT_GT(cv::norm(a, apply_sensor_model(grey, sensor, frame_seed(7, 1000, "stereo_right")), cv::NORM_L1), 0.0);
  EXPECT_GT(cv::norm(a, apply_sensor_model(grey, sensor, frame_seed(8, 1000, "stereo_left")), cv::NORM_L1), 0.0);
}

TEST(SensorModel, ExposureScalesAndSaturates) {
  const cv::Mat img(2, 2, CV_8UC3, cv::Scalar(100, 200, 10));
  SensorModel sensor;
  sensor.exposure_gain = 1.5;
  const cv::Mat out = apply_sensor_model(img, sensor, 1);
  EXPECT_EQ(out.at<cv::Vec3b>(0, 0), cv::Vec3b(150, 255, 15));
  sensor.exposure_gain = 1.0;
  sensor.black_level = 5.0;
  EXPECT_EQ(apply_sensor_model(img, sensor, 1).at<cv::Vec3b>(1, 1), cv::Vec3b(105, 205, 15));
}

TEST(SensorModel, FrameSeedsDiffer) {
  EXPECT_NE(frame_seed(1, 0, "a"), frame_seed(1, 0, "b"));
  EXPECT_NE(frame_seed(1, 0, "a"), frame_seed(2, 0, "a"));
  EXPECT_NE(frame_seed(1, 0, "a"), frame_seed(1, 1, "a"));
  EXPECT_EQ(frame_seed(1, 5, "a"), frame_seed(1, 5, "a"));
}

}  // namespace
}  // namespace bookgrasp::sim_render
