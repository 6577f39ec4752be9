#include "common/image_conversion.h"

#include <gtest/gtest.h>

#include <cmath>

#include <opencv2/imgcodecs.hpp>

namespace bookgrasp {
namespace {

cv::Mat pattern_rgb(int w, int h) {
  cv::Mat m(h, w, CV_8UC3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) m.at<cv::Vec3b>(y, x) = cv::Vec3b(x % 256, y % 256, (x * y) % 256);
  return m;
}

TEST(ImageConversion, RawRoundTripsEveryFormat) {
  const cv::Mat rgb = pattern_rgb(64, 48);
  cv::Mat gray;
  cv::extractChannel(rgb, gray, 0);
  cv::Mat depth(48, 64, CV_32FC1);
  cv::randu(depth, 0.3f, 3.0f);
  cv::Mat u16(48, 64, CV_16UC1);
  cv::randu(u16, 0, 65535);
  cv::Mat labels(48, 64, CV_32SC1);
  cv::randu(labels, 0, 1000);
  struct Case {
    cv::Mat m;
    int8_t f;
  };
  for (const auto& c : {Case{rgb, image_t::RGB8}, Case{gray, image_t::GRAY8}, Case{depth, image_t::DEPTH_F32},
                        Case{depth, image_t::DISPARITY_F32}, Case{u16, image_t::DEPTH_U16},
                        Case{labels, image_t::LABEL_I32}}) {
    const image_t msg = mat_to_image(c.m, c.f, 42, "cam");
    EXPECT_EQ(msg.size, static_cast<int32_t>(msg.data.size()));
    EXPECT_EQ(msg.utime, 42);
    const cv::Mat back = image_to_mat(msg);
    ASSERT_EQ(back.type(), c.m.type()) << pixel_format_name(c.f);
    EXPECT_EQ(cv::norm(back, c.m, cv::NORM_INF), 0.0) << pixel_format_name(c.f);
  }
}

TEST(ImageConversion, PaddedStrideIsHonoured) {
  const cv::Mat rgb = pattern_rgb(10, 4);
  image_t msg = mat_to_image(rgb, image_t::RGB8, 1, "cam");
  // Re-pack with 2 bytes of padding per row.
  std::vector<uint8_t> padded;
  for (int r = 0; r < 4; ++r) {
    padded.insert(padded.end(), msg.data.begin() + r * 30, msg.data.begin() + (r + 1) * 30);
    padded.push_back(0xEE);
    padded.push_back(0xEE);
  }
  msg.data = padded;
  msg.size = static_cast<int32_t>(padded.size());
  msg.row_stride = 32;
  EXPECT_EQ(cv::norm(image_to_mat(msg), rgb, cv::NORM_INF), 0.0);
}

TEST(ImageConversion, PngIsLosslessAndJpegClose) {
  const cv::Mat rgb = pattern_rgb(80, 60);
  const cv::Mat png = image_to_mat(encode_png(rgb, 5, "cam"));
  EXPECT_EQ(cv::norm(png, rgb, cv::NORM_INF), 0.0) << "PNG must keep RGB order and values";
  cv::Mat smooth(60, 80, CV_8UC3, cv::Scalar(200, 30, 90));
  const cv::Mat jpg = image_to_mat(encode_jpeg(smooth, 5, "cam", 95));
  EXPECT_LT(cv::norm(jpg, smooth, cv::NORM_INF), 6.0) << "JPEG must keep RGB order";
  cv::Mat u16(30, 40, CV_16UC1, cv::Scalar(1234));
  u16.at<uint16_t>(0, 0) = 0;
  const image_t dmsg = encode_png(u16, 5, "depth", 0.001f);
  const cv::Mat metres = depth_to_metres(dmsg);
  EXPECT_NEAR(metres.at<float>(10, 10), 1.234f, 1e-6);
  EXPECT_TRUE(std::isnan(metres.at<float>(0, 0))) << "0 counts means unknown depth";
}

std::string error_of(const image_t& m) {
  try {
    image_to_mat(m);
  } catch (const ImageError& e) {
    return e.what();
  }
  return "";
}

TEST(ImageConversion, BadMessagesGiveClearErrors) {
  const image_t good = mat_to_image(pattern_rgb(16, 8), image_t::RGB8, 1, "cam");
  image_t m = good;
  m.data.resize(10);
  m.size = 10;
  EXPECT_NE(error_of(m).find("needs row_stride * height"), std::string::npos) << error_of(m);
  m = good;
  m.size = 7;
  EXPECT_NE(error_of(m).find("size field"), std::string::npos);
  m = good;
  m.width = 0;
  EXPECT_NE(error_of(m).find("width and height"), std::string::npos);
  m = good;
  m.width = kMaxImageSide + 1;
  EXPECT_NE(error_of(m).find("width and height"), std::string::npos);
  m = good;
  m.row_stride = 10;
  EXPECT_NE(error_of(m).find("row_stride"), std::string::npos);
  m = good;
  m.pixel_format = 99;
  EXPECT_NE(error_of(m).find("unknown pixel format"), std::string::npos);
  m = good;
  m.pixel_format = image_t::PNG;
  EXPECT_NE(error_of(m).find("does not decode"), std::string::npos);
  image_t png = encode_png(pattern_rgb(16, 8), 1, "cam");
  png.width = 17;
  EXPECT_NE(error_of(png).find("decoded size"), std::string::npos);
  EXPECT_THROW(depth_to_metres(good), ImageError);
  image_t u16 = mat_to_image(cv::Mat(4, 4, CV_16UC1, cv::Scalar(3)), image_t::DEPTH_U16, 1, "d", 0.0f);
  EXPECT_THROW(depth_to_metres(u16), ImageError) << "16-bit depth without a scale";
  EXPECT_THROW(mat_to_image(pattern_rgb(4, 4), image_t::GRAY8, 1, "cam"), ImageError);
}

}  // namespace
}  // namespace bookgrasp

namespace bookgrasp {
namespace {

TEST(ImageConversion, EncodeImageByName) {
  cv::Mat rgb(48, 64, CV_8UC3, cv::Scalar(10, 120, 240));
  EXPECT_EQ(encode_image(rgb, "raw", 1, "c").pixel_format, image_t::RGB8);
  EXPECT_EQ(encode_image(rgb, "png", 1, "c").pixel_format, image_t::PNG);
  const image_t j = encode_image(rgb, "jpeg", 1, "c");
  EXPECT_EQ(j.pixel_format, image_t::JPEG);
  EXPECT_LT(cv::norm(image_to_mat(j), rgb, cv::NORM_INF), 4.0);
  cv::Mat gray(8, 8, CV_8UC1, cv::Scalar(7));
  EXPECT_EQ(encode_image(gray, "raw", 1, "c").pixel_format, image_t::GRAY8);
  EXPECT_THROW(encode_image(rgb, "webp", 1, "c"), ImageError);
}

}  // namespace
}  // namespace bookgrasp
