#include "common/sim_render/image_folder.h"

#include <gtest/gtest.h>

namespace bookgrasp::sim_render {
namespace {

const std::string kData = BOOKGRASP_SOURCE_DIR "/tests/data/middlebury";

TEST(ImageFolder, PairsTheMiddleburyViews) {
  const auto pairs = find_image_pairs(kData, "im2.png", "im6.png");
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0].left, kData + "/Cones/im2.png");
  EXPECT_EQ(pairs[0].right, kData + "/Cones/im6.png");
  EXPECT_EQ(pairs[1].left, kData + "/Teddy/im2.png");
  const cv::Mat img = read_rgb(pairs[1].right);
  EXPECT_EQ(img.type(), CV_8UC3);
  EXPECT_EQ(img.cols, 450);
  EXPECT_EQ(img.rows, 375);
  // Grey images come out as three equal channels.
  const cv::Mat disp = read_rgb(kData + "/Teddy/disp2.png");
  EXPECT_EQ(disp.type(), CV_8UC3);
}

TEST(ImageFolder, MissingPartnersAndEmptyFoldersAreErrors) {
  EXPECT_THROW(find_image_pairs(kData, "im2.png", "im9.png"), std::runtime_error);
  EXPECT_THROW(find_image_pairs(kData, "nothing.png", "im6.png"), std::runtime_error);
  EXPECT_THROW(find_image_pairs(kData + "/nope", "im2.png", "im6.png"), std::runtime_error);
  EXPECT_THROW(find_images(kData, ".jpg"), std::runtime_error);
  EXPECT_EQ(find_images(kData, "occl.png").size(), 2u);
  EXPECT_THROW(read_rgb(kData + "/Teddy/missing.png"), std::runtime_error);
}

}  // namespace
}  // namespace bookgrasp::sim_render
