#pragma once
/// @file
/// Image files of a folder, for the `files` backends of the camera services.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace bookgrasp::sim_render {

/// The two files of one stereo pair.
struct ImagePairFiles {
  std::string left;   ///< path of the left image
  std::string right;  ///< path of the right image
};

/// Every file under `folder` (recursively) whose name ends with `left_suffix`,
/// paired with the file of the same path ending in `right_suffix` instead;
/// sorted by path. E.g. suffixes "im2.png" / "im6.png" for the Middlebury
/// scenes, "_left.png" / "_right.png" for "0001_left.png". Throws
/// std::runtime_error if the folder cannot be read, a left image has no
/// right partner, or nothing matches.
std::vector<ImagePairFiles> find_image_pairs(const std::string& folder, const std::string& left_suffix,
                                             const std::string& right_suffix);

/// Every file under `folder` (recursively) whose name ends with `suffix`,
/// sorted by path. Throws std::runtime_error if none or unreadable.
std::vector<std::string> find_images(const std::string& folder, const std::string& suffix);

/// Reads an image file as CV_8UC3 RGB (grey images are expanded). Throws
/// std::runtime_error naming the file if it cannot be decoded.
cv::Mat read_rgb(const std::string& path);

}  // namespace bookgrasp::sim_render
