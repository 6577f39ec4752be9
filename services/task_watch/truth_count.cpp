#include "services/task_watch/truth_count.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace bookgrasp {

double height_axis_tilt_deg(const pose_t& pose) {
  const double w = pose.orientation[0], x = pose.orientation[1], y = pose.orientation[2], z = pose.orientation[3];
  const double n2 = w * w + x * x + y * y + z * z;
  if (!(n2 > 0)) return NAN;
  const double up_z = (w * w - x * x - y * y + z * z) / n2;  // R(2,2) of the quaternion
  return std::acos(std::clamp(up_z, -1.0, 1.0)) * 180.0 / M_PI;
}

TruthCount count_books_by_place(const ground_truth_t& gt) {
  TruthCount c;
  for (const book_truth_t& b : gt.books) {
    ++c.books;
    if (b.place == "lower_shelf") {
      ++c.lower_shelf;
      c.lower_shelf_upright += height_axis_tilt_deg(b.pose) <= kUprightMaxTiltDeg ? 1 : 0;
    } else if (b.place == "upper_shelf") {
      ++c.upper_shelf;
    } else if (b.place == "holder") {
      ++c.holder;
    } else if (b.place == "gripper") {
      ++c.gripper;
    } else if (b.place == "other") {
      ++c.other;
    } else {
      ++c.unknown_place;
    }
  }
  return c;
}

std::string truth_summary(const TruthCount& c, double message_s) {
  std::ostringstream o;
  o.setf(std::ios::fixed);
  o.precision(1);
  o << "simulation truth at " << message_s << " s: of " << c.books << " books, " << c.lower_shelf
    << " on the lower shelf (" << c.lower_shelf_upright << " of them standing upright), " << c.upper_shelf
    << " on the upper shelf, " << c.holder << " on the holder, " << c.gripper << " in the gripper, " << c.other
    << " elsewhere (taken by the librarian, or fallen off the cart)";
  if (c.unknown_place > 0) o << ", " << c.unknown_place << " at a place this tool does not know";
  return o.str();
}

}  // namespace bookgrasp
