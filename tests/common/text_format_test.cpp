// format_text: numbers of several types into one string, and a text longer than any fixed buffer.
#include "common/text_format.h"

#include <gtest/gtest.h>

#include <string>

namespace bookgrasp {
namespace {

TEST(TextFormat, FillsTheConversions) {
  EXPECT_EQ(format_text("%zu views, need %d, moved %.1f mm", size_t{3}, 4, 12.345), "3 views, need 4, moved 12.3 mm");
}

TEST(TextFormat, LongTextIsNotCut) {
  const std::string long_word(1000, 'x');
  EXPECT_EQ(format_text("[%s]", long_word.c_str()), "[" + long_word + "]");
}

}  // namespace
}  // namespace bookgrasp
