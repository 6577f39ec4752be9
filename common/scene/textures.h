#pragma once
/// @file
/// Images used as textures by the simulated scene (OpenCV, RGB order, 8 bit).

#include <opencv2/core.hpp>

#include "common/scene/scene.h"

namespace bookgrasp::scene {

/// The fore-edge (page edges) of `book` as an RGB image: columns run across the
/// thickness (column 0 = the book's right side, -y), rows along the height
/// (row 0 = top). Off-white with fine page lines, thin cover edges at both
/// sides and the book's stamps. Deterministic in book.texture_seed.
cv::Mat page_edge_texture(const Book& book, const RenderSettings& render);

/// An AprilTag tag36h11 marker `id` as an RGB image including its one-cell
/// white border (10 x 10 cells), `px_per_cell` pixels per cell. Row 0 = top of
/// the printed tag. Throws std::invalid_argument for an id outside 0..586.
cv::Mat apriltag_texture(int id, int px_per_cell);

}  // namespace bookgrasp::scene
