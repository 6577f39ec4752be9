#include "common/sim_render/image_folder.h"

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace bookgrasp::sim_render {
namespace fs = std::filesystem;
namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::vector<std::string> files_ending(const std::string& folder, const std::string& suffix) {
  if (suffix.empty()) throw std::runtime_error("image file suffix must not be empty");
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) throw std::runtime_error("image folder '" + folder + "' is not a folder");
  std::vector<std::string> out;
  for (fs::recursive_directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->is_regular_file() && ends_with(it->path().filename().string(), suffix)) {
      out.push_back(it->path().string());
    }
  }
  if (ec) throw std::runtime_error("cannot read image folder '" + folder + "': " + ec.message());
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

std::vector<ImagePairFiles> find_image_pairs(const std::string& folder, const std::string& left_suffix,
                                             const std::string& right_suffix) {
  if (left_suffix == right_suffix) throw std::runtime_error("left and right image suffixes are the same");
  std::vector<ImagePairFiles> pairs;
  for (const std::string& left : files_ending(folder, left_suffix)) {
    ImagePairFiles p;
    p.left = left;
    p.right = left.substr(0, left.size() - left_suffix.size()) + right_suffix;
    if (!fs::is_regular_file(p.right)) {
      throw std::runtime_error("left image '" + left + "' has no right image '" + p.right + "'");
    }
    pairs.push_back(p);
  }
  if (pairs.empty()) {
    throw std::runtime_error("no image pairs '*" + left_suffix + "' / '*" + right_suffix + "' under '" + folder +
                             "'");
  }
  return pairs;
}

std::vector<std::string> find_images(const std::string& folder, const std::string& suffix) {
  std::vector<std::string> out = files_ending(folder, suffix);
  if (out.empty()) throw std::runtime_error("no images '*" + suffix + "' under '" + folder + "'");
  return out;
}

cv::Mat read_rgb(const std::string& path) {
  const cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR);
  if (bgr.empty()) throw std::runtime_error("cannot decode image '" + path + "'");
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return rgb;
}

}  // namespace bookgrasp::sim_render
