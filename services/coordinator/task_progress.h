#pragma once
/// @file
/// The coordinator's progress, persisted so a restarted coordinator resumes
/// without losing or dropping a book: how many books were moved, where the
/// current book is (upper shelf, in the gripper, on the holder), what is known
/// about it, and the next free slot on the lower shelf. Written atomically
/// (temporary file, fsync, rename). No LCM.

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace bookgrasp {

/// Where the current book physically is.
enum class BookPlace {
  kUpperShelf,           ///< not taken yet (or no current book)
  kInGripperFromShelf,   ///< grasped from the upper shelf, not yet released on the holder
  kOnHolder,             ///< released on the holder, waiting for the user
  kInGripperFromHolder,  ///< grasped from the holder, not yet released on the lower shelf
};

/// Name of a place ("upper_shelf", "gripper_from_shelf", "holder", "gripper_from_holder").
std::string book_place_name(BookPlace p);

/// One book that completed the cycle.
struct MovedBook {
  int index = 0;              ///< 0 = first book taken
  double width = 0;           ///< from the gripper plates, m
  double gp_y = 0;            ///< grasp-frame Y of its GP (its right cover on the upper shelf), m
  double lower_right_y = 0;   ///< grasp-frame Y of its right cover on the lower shelf, m (handed over: NaN)
  /// Too tall for, or not placeable on, the lower shelf: left on the holder and taken off it by the librarian
  /// (WAIT_BOOK_TAKEN).
  bool handed_over = false;
  /// Its height (GP.x: the top's height over the shelf it was taken from), m; NaN in progress files written before
  /// stop 32 (then the placed book's box for the planner is as tall as the lower shelf takes).
  double height = std::numeric_limits<double>::quiet_NaN();
};

/// Everything persisted.
struct TaskProgress {
  int books_moved = 0;                    ///< completed cycles (lower shelf, or handed over: MovedBook)
  int failures = 0;                       ///< failures (each retried or aborting), all books
  BookPlace place = BookPlace::kUpperShelf;  ///< where the current book is
  bool have_book_data = false;            ///< gp_grasp and book_width below are set
  Eigen::Vector3d gp_grasp = Eigen::Vector3d::Zero();  ///< current book's GP, grasp frame
  double book_width = 0;                  ///< current book's width (plates), m
  /// How far beyond GP the plates went at the current book's last INSERT, m (less than grasp.insertion_depth_m near
  /// the right side panel): EXTRACT and BACK_OUT come out as far, and the planner's box for the held book reaches that
  /// much further ahead. NaN before the first INSERT and in files written before stop 38 (then recomputed).
  double grasp_insertion_depth = std::numeric_limits<double>::quiet_NaN();
  double lower_next_right_y = 0;          ///< right cover of the next book on the lower shelf, grasp Y
  bool finished = false;                  ///< the upper shelf is empty
  /// Non-empty: why the lower shelf could not take the current book; it goes back onto the holder for the librarian.
  std::string hand_over_reason;
  std::string last_state;                 ///< state-machine state when written
  std::vector<MovedBook> moved;           ///< the books moved, in order
  /// The cart and holder marker poses (base) last seen: the cart and the holder stand still through a task. A
  /// restarted coordinator that does not see a tag within timeouts.markers_s (the held book or the stopped arm in
  /// front of it) resumes with these. Absent before the first sighting and in files written before stop 40.
  std::optional<Eigen::Isometry3d> cart_marker_in_base;
  std::optional<Eigen::Isometry3d> holder_marker_in_base;  ///< see cart_marker_in_base
};

/// The progress as YAML text.
std::string progress_to_yaml(const TaskProgress& p);
/// Parses progress YAML; throws std::runtime_error naming the bad key.
TaskProgress progress_from_yaml(const std::string& text, const std::string& source);
/// Writes `p` to `path` atomically (write `path`.tmp, fsync, rename). Throws std::runtime_error on failure.
void save_progress(const std::string& path, const TaskProgress& p);
/// Reads `path`; nullopt if it does not exist. Throws std::runtime_error if it exists but cannot be parsed.
std::optional<TaskProgress> load_progress(const std::string& path);

}  // namespace bookgrasp
