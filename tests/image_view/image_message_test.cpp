#include "services/image_view/image_message.h"

#include <gtest/gtest.h>

#include <vector>

#include "bookgrasp/pose_t.hpp"
#include "bookgrasp/stereo_frame_t.hpp"
#include "common/image_conversion.h"

namespace bookgrasp {
namespace {

template <typename Msg>
std::vector<uint8_t> encode(const Msg& m) {
  std::vector<uint8_t> b(m.getEncodedSize());
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

TEST(ImageMessage, DecodesEveryImageCarrierAndNothingElse) {
  cv::Mat rgb(30, 40, CV_8UC3, cv::Scalar(200, 10, 60));
  const auto img = encode(encode_png(rgb, 77, "debug"));
  auto p = decode_picture(img.data(), static_cast<int>(img.size()));
  ASSERT_TRUE(p);
  EXPECT_EQ(p->type, "image_t");
  EXPECT_EQ(p->utime, 77);
  EXPECT_EQ(cv::norm(p->rgb, rgb, cv::NORM_INF), 0.0);

  stereo_frame_t s{};
  s.utime = 5;
  s.left = mat_to_image(rgb, image_t::RGB8, 5, "l");
  s.right = mat_to_image(cv::Mat(30, 40, CV_8UC3, cv::Scalar(1, 2, 3)), image_t::RGB8, 5, "r");
  const auto sb = encode(s);
  p = decode_picture(sb.data(), static_cast<int>(sb.size()));
  ASSERT_TRUE(p);
  EXPECT_EQ(p->rgb.cols, 80) << "left and right side by side";
  EXPECT_EQ(p->rgb.at<cv::Vec3b>(0, 0), cv::Vec3b(200, 10, 60));
  EXPECT_EQ(p->rgb.at<cv::Vec3b>(0, 79), cv::Vec3b(1, 2, 3));

  cv::Mat depth(20, 20, CV_32FC1, cv::Scalar(1.0f));
  depth.at<float>(0, 0) = std::numeric_limits<float>::quiet_NaN();
  depth.at<float>(5, 5) = 2.0f;
  const auto db = encode(mat_to_image(depth, image_t::DEPTH_F32, 1, "d"));
  p = decode_picture(db.data(), static_cast<int>(db.size()));
  ASSERT_TRUE(p);
  EXPECT_EQ(p->rgb.type(), CV_8UC3) << "depth is colour-mapped";
  EXPECT_EQ(p->rgb.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0)) << "unknown depth (NaN) is black";
  EXPECT_NE(p->rgb.at<cv::Vec3b>(10, 10), cv::Vec3b(0, 0, 0)) << "known depth is not";
  EXPECT_NE(p->rgb.at<cv::Vec3b>(5, 5), p->rgb.at<cv::Vec3b>(10, 10)) << "far and near differ in colour";

  pose_t other{};
  const auto ob = encode(other);
  EXPECT_FALSE(decode_picture(ob.data(), static_cast<int>(ob.size())));
  EXPECT_FALSE(decode_picture(ob.data(), 4));
  auto bad = img;
  bad[bad.size() / 2] ^= 0xFF;  // corrupt the PNG payload
  EXPECT_ANY_THROW({
    auto r = decode_picture(bad.data(), static_cast<int>(bad.size()));
    if (!r) throw std::runtime_error("not decoded");
  });
}

}  // namespace
}  // namespace bookgrasp
