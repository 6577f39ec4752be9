#pragma once
/// @file
/// Hand-made scene outcomes for the evaluation's tests, with their figures worked out in the comments.

#include <string>

#include "services/eval_full/full_cycle_metrics.h"

namespace bookgrasp {
namespace test_scenes {

/// A book of the final truth at `place`.
inline book_truth_t truth_book(const std::string& place, int id = 0) {
  book_truth_t b{};
  b.id = id;
  b.place = place;
  b.pose.orientation[0] = 1.0;  // upright: the book's height axis along base Z
  return b;
}

/// A scene whose cycle moved both of its two books, one grasp retried; two GRASP decisions with P1, one without.
inline SceneOutcome done_scene(uint64_t seed) {
  SceneOutcome o;
  o.seed = seed;
  FullCycleResult& r = o.result;
  r.end = "DONE";
  r.books_on_upper_shelf = 2;
  r.books_moved = 2;
  r.grasp_attempts = 3;  // one retry
  r.grasp_successes = 2;
  r.holder_releases = 2;
  r.holder_placed = 2;
  r.holder_standing = 2;
  r.final_truth.books = {truth_book("lower_shelf", 0), truth_book("lower_shelf", 1)};
  r.final_truth.num_books = 2;
  BookRecord a;
  a.truth_id = 0;
  a.true_width_m = 0.020;
  a.measured_width_m = 0.023;  // 3 mm
  a.grasp_attempts = 1;
  a.grasp_successes = 1;  // the plates closed on the book (physics)
  a.moved = true;
  a.place_after_holder_release = "holder";
  a.standing_on_holder = 1;
  a.start_s = 0;
  a.end_s = 100;
  BookRecord b = a;
  b.truth_id = 1;
  b.measured_width_m = 0.035;  // 15 mm: outside 1 cm
  b.start_s = 100;
  b.end_s = 220;
  BookRecord c;  // a close on nothing: its plate distance is no book width and is not counted
  c.truth_id = 2;
  c.true_width_m = 0.020;
  c.measured_width_m = 0.0;
  c.grasp_attempts = 1;
  r.books = {a, b, c};
  GraspDecisionRecord d;
  d.p1_present = true;
  d.p1_grasp = {0.20, 0.10, 0.01};
  d.p2_grasp = {0.21, 0.11, 0.01};  // dY 10 mm, dX 10 mm: agree
  d.gp_grasp = {0.20, 0.11, 0.01};
  d.truth_known = true;
  d.p1_true_grasp = {0.204, 0.10, 0.013};
  d.gp_base_true_grasp = {0.210, 0.11, -0.007};  // the cart frame 10 mm high and 20 mm short
  GraspDecisionRecord e = d;
  e.p2_grasp = {0.20, 0.12, 0.01};  // dY 20 mm: disagree
  e.gp_grasp = {0.20, 0.12, 0.01};
  GraspDecisionRecord no_p1;
  no_p1.p1_present = false;
  r.decisions = {d, e, no_p1};
  return o;
}

}  // namespace test_scenes
}  // namespace bookgrasp
