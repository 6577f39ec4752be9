// Every message type: fill, encode, decode, compare field by field and byte by byte.
#include <gtest/gtest.h>

#include <vector>

#include "bookgrasp/all_types.hpp"
#include "common/image_conversion.h"
#include "tests/common/lcm_fill.hpp"

namespace bookgrasp_test {
namespace {

template <typename T>
void round_trip(const char* name) {
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    T a{};
    FillRng rng(seed);
    fill(a, rng);
    const int size = a.getEncodedSize();
    ASSERT_GT(size, 0) << name;
    std::vector<uint8_t> buf(size);
    ASSERT_EQ(a.encode(buf.data(), 0, size), size) << name << " seed " << seed;
    T b{};
    ASSERT_EQ(b.decode(buf.data(), 0, size), size) << name << " seed " << seed;
    EXPECT_TRUE(equal(a, b)) << name << " differs after a round trip, seed " << seed;
    std::vector<uint8_t> again(b.getEncodedSize());
    ASSERT_EQ(b.encode(again.data(), 0, static_cast<int>(again.size())), static_cast<int>(again.size()));
    EXPECT_EQ(buf, again) << name;
    // Every message starts with int64_t utime, right after the fingerprint.
    EXPECT_EQ(a.utime, b.utime) << name;
  }
  // A different seed must give a different message (the filler is not constant).
  T x{}, y{};
  FillRng r1(1), r2(2);
  fill(x, r1);
  fill(y, r2);
  EXPECT_FALSE(equal(x, y)) << name << ": filler produced identical messages for different seeds";
}

TEST(LcmTypesRoundTrip, EveryType) {
  int types = 0;
#define BOOKGRASP_ROUND_TRIP(T) \
  round_trip<bookgrasp::T>(#T);  \
  ++types;
  BOOKGRASP_FOR_EACH_TYPE(BOOKGRASP_ROUND_TRIP)
#undef BOOKGRASP_ROUND_TRIP
  EXPECT_GE(types, 30);
}

TEST(LcmTypesRoundTrip, DecodeOfAnotherTypeFails) {
  bookgrasp::pose_t p;
  FillRng rng(3);
  fill(p, rng);
  std::vector<uint8_t> buf(p.getEncodedSize());
  p.encode(buf.data(), 0, static_cast<int>(buf.size()));
  bookgrasp::task_status_t wrong;
  EXPECT_LT(wrong.decode(buf.data(), 0, static_cast<int>(buf.size())), 0);
  // Truncated data fails too.
  bookgrasp::pose_t q;
  EXPECT_LT(q.decode(buf.data(), 0, static_cast<int>(buf.size()) - 5), 0);
}

TEST(LcmTypesRoundTrip, LargestSupportedImage) {
  // kMaxImageSide x kMaxImageSide, 4 bytes per pixel (DEPTH_F32): the largest image_t accepted.
  bookgrasp::stereo_frame_t f{};
  f.utime = 123456789;
  auto& img = f.left;
  img.utime = f.utime;
  img.frame = "stereo_left";
  img.width = bookgrasp::kMaxImageSide;
  img.height = bookgrasp::kMaxImageSide;
  img.pixel_format = bookgrasp::image_t::DEPTH_F32;
  img.row_stride = img.width * 4;
  img.data.resize(static_cast<size_t>(img.row_stride) * img.height);
  for (size_t i = 0; i < img.data.size(); i += 4097) img.data[i] = static_cast<uint8_t>(i * 31);
  img.size = static_cast<int32_t>(img.data.size());
  const int size = f.getEncodedSize();
  std::vector<uint8_t> buf(size);
  ASSERT_EQ(f.encode(buf.data(), 0, size), size);
  bookgrasp::stereo_frame_t g{};
  ASSERT_EQ(g.decode(buf.data(), 0, size), size);
  EXPECT_TRUE(equal(f, g));
  EXPECT_EQ(g.left.data, img.data);
}

}  // namespace
}  // namespace bookgrasp_test
