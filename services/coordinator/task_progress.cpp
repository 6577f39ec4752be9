#include "services/coordinator/task_progress.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "common/pose_conversion.h"

namespace bookgrasp {

std::string book_place_name(BookPlace p) {
  switch (p) {
    case BookPlace::kUpperShelf: return "upper_shelf";
    case BookPlace::kInGripperFromShelf: return "gripper_from_shelf";
    case BookPlace::kOnHolder: return "holder";
    case BookPlace::kInGripperFromHolder: return "gripper_from_holder";
  }
  return "?";
}

namespace {
BookPlace place_from_name(const std::string& s, const std::string& source) {
  for (BookPlace p : {BookPlace::kUpperShelf, BookPlace::kInGripperFromShelf, BookPlace::kOnHolder,
                      BookPlace::kInGripperFromHolder})
    if (book_place_name(p) == s) return p;
  throw std::runtime_error(source + ": place '" + s +
                           "' is not one of upper_shelf, gripper_from_shelf, holder, gripper_from_holder");
}

template <typename T>
T need(const YAML::Node& n, const std::string& key, const std::string& source) {
  if (!n[key]) throw std::runtime_error(source + ": missing key '" + key + "' (a truncated or foreign progress file?)");
  try {
    return n[key].as<T>();
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(source + ": key '" + key + "' has the wrong type: " + e.what());
  }
}
/// A pose as [x, y, z, qw, qx, qy, qz] (the YAML form of the marker poses), as pose_t orders it.
void emit_pose(YAML::Emitter& e, const char* key, const std::optional<Eigen::Isometry3d>& pose) {
  if (!pose) return;
  const pose_t p = isometry_to_pose(*pose, "base", key, 0);
  e << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq << p.position[0] << p.position[1]
    << p.position[2] << p.orientation[0] << p.orientation[1] << p.orientation[2] << p.orientation[3] << YAML::EndSeq;
}

std::optional<Eigen::Isometry3d> parse_pose(const YAML::Node& n, const std::string& key, const std::string& source) {
  if (!n[key]) return std::nullopt;
  const auto v = need<std::vector<double>>(n, key, source);
  if (v.size() != 7) throw std::runtime_error(source + ": '" + key + "' must be 7 numbers [x, y, z, qw, qx, qy, qz]");
  pose_t p;
  p.utime = 0;
  p.frame = "base";
  p.child = key;
  std::copy(v.begin(), v.begin() + 3, p.position);
  std::copy(v.begin() + 3, v.end(), p.orientation);
  try {
    return pose_to_isometry(p);
  } catch (const PoseError& e) {
    throw std::runtime_error(source + ": '" + key + "': " + e.what());
  }
}
}  // namespace

std::string progress_to_yaml(const TaskProgress& p) {
  YAML::Emitter e;
  e.SetDoublePrecision(17);
  e << YAML::BeginMap;
  e << YAML::Key << "books_moved" << YAML::Value << p.books_moved;
  e << YAML::Key << "failures" << YAML::Value << p.failures;
  e << YAML::Key << "place" << YAML::Value << book_place_name(p.place);
  e << YAML::Key << "have_book_data" << YAML::Value << p.have_book_data;
  e << YAML::Key << "gp_grasp" << YAML::Value << YAML::Flow << YAML::BeginSeq << p.gp_grasp.x() << p.gp_grasp.y()
    << p.gp_grasp.z() << YAML::EndSeq;
  e << YAML::Key << "book_width" << YAML::Value << p.book_width;
  e << YAML::Key << "grasp_insertion_depth" << YAML::Value << p.grasp_insertion_depth;
  e << YAML::Key << "lower_next_right_y" << YAML::Value << p.lower_next_right_y;
  e << YAML::Key << "finished" << YAML::Value << p.finished;
  e << YAML::Key << "last_state" << YAML::Value << p.last_state;
  e << YAML::Key << "hand_over_reason" << YAML::Value << p.hand_over_reason;
  e << YAML::Key << "moved" << YAML::Value << YAML::BeginSeq;
  for (const MovedBook& b : p.moved)
    e << YAML::Flow << YAML::BeginMap << YAML::Key << "index" << YAML::Value << b.index << YAML::Key << "width"
      << YAML::Value << b.width << YAML::Key << "gp_y" << YAML::Value << b.gp_y << YAML::Key << "lower_right_y"
      << YAML::Value << b.lower_right_y << YAML::Key << "handed_over" << YAML::Value << b.handed_over << YAML::Key
      << "height" << YAML::Value << b.height << YAML::EndMap;
  e << YAML::EndSeq;
  emit_pose(e, "cart_marker_in_base", p.cart_marker_in_base);
  emit_pose(e, "holder_marker_in_base", p.holder_marker_in_base);
  e << YAML::EndMap;
  return std::string(e.c_str()) + "\n";
}

TaskProgress progress_from_yaml(const std::string& text, const std::string& source) {
  YAML::Node n;
  try {
    n = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(source + ": not valid YAML: " + e.what());
  }
  if (!n.IsMap()) throw std::runtime_error(source + ": the progress file is not a YAML mapping");
  TaskProgress p;
  p.books_moved = need<int>(n, "books_moved", source);
  p.failures = need<int>(n, "failures", source);
  p.place = place_from_name(need<std::string>(n, "place", source), source);
  p.have_book_data = need<bool>(n, "have_book_data", source);
  const auto gp = need<std::vector<double>>(n, "gp_grasp", source);
  if (gp.size() != 3) throw std::runtime_error(source + ": gp_grasp must have 3 numbers");
  p.gp_grasp = Eigen::Vector3d(gp[0], gp[1], gp[2]);
  p.book_width = need<double>(n, "book_width", source);
  // Absent before stop 38: recomputed from the plates' opening and GP.
  if (n["grasp_insertion_depth"]) p.grasp_insertion_depth = need<double>(n, "grasp_insertion_depth", source);
  p.lower_next_right_y = need<double>(n, "lower_next_right_y", source);
  p.finished = need<bool>(n, "finished", source);
  p.last_state = need<std::string>(n, "last_state", source);
  // Absent before stop 25 (no book was handed over for any reason but its height then).
  p.hand_over_reason = n["hand_over_reason"] ? need<std::string>(n, "hand_over_reason", source) : std::string();
  const YAML::Node moved = n["moved"];
  if (!moved || !moved.IsSequence()) throw std::runtime_error(source + ": missing list 'moved'");
  for (const YAML::Node& b : moved) {
    MovedBook m;
    m.index = need<int>(b, "index", source);
    m.width = need<double>(b, "width", source);
    m.gp_y = need<double>(b, "gp_y", source);
    m.lower_right_y = need<double>(b, "lower_right_y", source);
    m.handed_over = b["handed_over"] ? need<bool>(b, "handed_over", source) : false;  // absent before stop 22
    m.height = b["height"] ? need<double>(b, "height", source) : std::numeric_limits<double>::quiet_NaN();  // stop 32
    p.moved.push_back(m);
  }
  p.cart_marker_in_base = parse_pose(n, "cart_marker_in_base", source);  // absent before stop 40
  p.holder_marker_in_base = parse_pose(n, "holder_marker_in_base", source);
  if (p.books_moved < 0 || p.books_moved != static_cast<int>(p.moved.size()))
    throw std::runtime_error(source + ": books_moved (" + std::to_string(p.books_moved) +
                             ") does not match the list 'moved' (" + std::to_string(p.moved.size()) + " entries)");
  return p;
}

void save_progress(const std::string& path, const TaskProgress& p) {
  const std::string tmp = path + ".tmp";
  const std::string text = progress_to_yaml(p);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) throw std::runtime_error("cannot write progress file " + tmp + ": " + std::strerror(errno));
  size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0) {
      const std::string err = std::strerror(errno);
      ::close(fd);
      throw std::runtime_error("cannot write progress file " + tmp + ": " + err);
    }
    done += static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0 || ::close(fd) != 0)
    throw std::runtime_error("cannot flush progress file " + tmp + ": " + std::strerror(errno));
  if (std::rename(tmp.c_str(), path.c_str()) != 0)
    throw std::runtime_error("cannot rename " + tmp + " to " + path + ": " + std::strerror(errno));
}

std::optional<TaskProgress> load_progress(const std::string& path) {
  std::ifstream in(path);
  if (!in) return std::nullopt;
  std::stringstream ss;
  ss << in.rdbuf();
  return progress_from_yaml(ss.str(), path);
}

}  // namespace bookgrasp
