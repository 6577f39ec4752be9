#pragma once
/// @file
/// The ground truth of a scene as JSON (every field of ground_truth_t).

#include <string>

#include "bookgrasp/ground_truth_t.hpp"

namespace bookgrasp::snapshot {

/// `truth` as a JSON object with the message's field names; poses as
/// {"frame", "child", "position": [x, y, z], "orientation_wxyz": [w, x, y, z]},
/// corners as 8 [x, y, z] arrays (index bits: 0 = back, 1 = left, 2 = top).
/// Numbers are written with 17 significant digits (round-trip exact).
std::string ground_truth_json(const ground_truth_t& truth);

}  // namespace bookgrasp::snapshot
