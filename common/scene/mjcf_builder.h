#pragma once
/// @file
/// Writes the MJCF of a scene (robot from the URDF + static scene + books +
/// cameras + lights) and the PNG textures it references, all in memory.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "common/scene/scene.h"

namespace bookgrasp::scene {

/// An MJCF document and the files it references (name -> bytes).
struct MjcfDocument {
  std::string xml;
  std::vector<std::pair<std::string, std::vector<uint8_t>>> files;
};

/// Builds the MJCF of `scene`. Reads the URDF (scene.urdf_path) with urdfdom.
/// Throws std::runtime_error naming the file if the URDF cannot be parsed or
/// lacks a link/joint the simulation needs.
MjcfDocument build_mjcf(const Scene& scene);

}  // namespace bookgrasp::scene
