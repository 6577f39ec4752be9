// The simulation's truth counted by place, as bookgrasp_task prints it beside the coordinator's count.
#include "services/task_watch/truth_count.h"

#include <gtest/gtest.h>

#include <cmath>

namespace bookgrasp {
namespace {

ground_truth_t truth_with(const std::vector<std::string>& places) {
  ground_truth_t gt{};
  for (size_t i = 0; i < places.size(); ++i) {
    book_truth_t b{};
    b.id = static_cast<int32_t>(i);
    b.place = places[i];
    b.pose.orientation[0] = 1.0;  // upright
    gt.books.push_back(b);
  }
  gt.num_books = static_cast<int32_t>(gt.books.size());
  return gt;
}

// The deployed main job of 2026-12-04 17:45 (far_cart seed 1) ended with 4 books on the lower shelf and 6 elsewhere,
// while the coordinator counted 6 on the lower shelf and 1 handed over.
TEST(TruthCount, CountsEveryPlaceAndSaysSo) {
  const TruthCount c = count_books_by_place(truth_with({"lower_shelf", "lower_shelf", "lower_shelf", "other", "other",
                                                        "other", "other", "other", "other", "lower_shelf"}));
  EXPECT_EQ(c.books, 10);
  EXPECT_EQ(c.lower_shelf, 4);
  EXPECT_EQ(c.other, 6);
  EXPECT_EQ(c.upper_shelf + c.holder + c.gripper + c.unknown_place, 0);
  EXPECT_EQ(truth_summary(c, 535.3),
            "simulation truth at 535.3 s: of 10 books, 4 on the lower shelf (4 of them standing upright), 0 on the "
            "upper shelf, 0 on the holder, 0 in the gripper, 6 elsewhere (taken by the librarian, or fallen off the "
            "cart)");
}

// The deployed main job of 2026-12-05 12:00 (far_cart seed 1): 8 books on the lower shelf, none standing (lying at
// 90 deg, or at 70 deg on another). A book leaning 15 deg on its neighbour still stands.
TEST(TruthCount, BooksOnTheLowerShelfAreCountedStandingOnlyWhenUpright) {
  ground_truth_t gt = truth_with({"lower_shelf", "lower_shelf", "lower_shelf", "holder"});
  auto turn = [](book_truth_t* b, double deg) {
    b->pose.orientation[0] = std::cos(deg * M_PI / 360);
    b->pose.orientation[2] = std::sin(deg * M_PI / 360);  // about base Y
  };
  turn(&gt.books[0], 90);
  turn(&gt.books[1], 70);
  turn(&gt.books[2], 15);
  turn(&gt.books[3], 90);  // not on the lower shelf: not counted either way
  EXPECT_NEAR(height_axis_tilt_deg(gt.books[1].pose), 70, 1e-9);
  const TruthCount c = count_books_by_place(gt);
  EXPECT_EQ(c.lower_shelf, 3);
  EXPECT_EQ(c.lower_shelf_upright, 1);
  EXPECT_NE(truth_summary(c, 1.0).find("3 on the lower shelf (1 of them standing upright)"), std::string::npos);
  pose_t zero{};
  EXPECT_TRUE(std::isnan(height_axis_tilt_deg(zero)));
}

TEST(TruthCount, APlaceItDoesNotKnowIsCountedApartAndNamed) {
  const TruthCount c = count_books_by_place(truth_with({"upper_shelf", "holder", "gripper", "floor"}));
  EXPECT_EQ(c.upper_shelf, 1);
  EXPECT_EQ(c.holder, 1);
  EXPECT_EQ(c.gripper, 1);
  EXPECT_EQ(c.other, 0);
  EXPECT_EQ(c.unknown_place, 1);
  EXPECT_NE(truth_summary(c, 1.0).find("1 at a place this tool does not know"), std::string::npos);
  EXPECT_EQ(count_books_by_place(ground_truth_t{}).books, 0);
}

}  // namespace
}  // namespace bookgrasp
