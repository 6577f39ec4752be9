#pragma once
/// @file
/// Where the simulation's books really are (SIM_GROUND_TRUTH), to set beside the coordinator's own count at the
/// end of a task: a book the coordinator counts as moved may have fallen off the lower shelf, and a grasp may have
/// carried its neighbour along. Simulation only (a real robot publishes no ground truth). Pure: no LCM.

#include <string>

#include "bookgrasp/ground_truth_t.hpp"

namespace bookgrasp {

/// A book stands when its height axis is within this of the vertical (books lean on each other a few degrees; a
/// knocked-over one lies at 90).
constexpr double kUprightMaxTiltDeg = 20.0;

/// The tilt of a book's height axis (its body Z, scene.cpp's corners) from base Z, degrees, for its truth `pose`;
/// NaN for a zero quaternion.
double height_axis_tilt_deg(const pose_t& pose);

/// Books per `book_truth_t.place`.
struct TruthCount {
  int books = 0;
  int lower_shelf = 0;
  int lower_shelf_upright = 0;  ///< ... of them standing (height_axis_tilt_deg <= kUprightMaxTiltDeg)
  int upper_shelf = 0;
  int holder = 0;
  int gripper = 0;
  int other = 0;          ///< taken out of the scene by the simulated librarian, or fallen off the cart
  int unknown_place = 0;  ///< a place name this tool does not know (a newer simulation)
};

/// Counts the books of `gt` by place.
TruthCount count_books_by_place(const ground_truth_t& gt);

/// One line for people: "simulation truth at <t> s: of N books, a on the lower shelf, ...".
/// `message_s`: the truth's message time in seconds, from the task's first status (to match with the task's end).
std::string truth_summary(const TruthCount& c, double message_s);

}  // namespace bookgrasp
