#pragma once
/// @file
/// P1 over several still stereo frames (not in the paper). The simulated and the real stereo camera put a new pixel
/// noise on every frame, and on about one scene in six it decides whether GoD joins a front's top to the rest or
/// lets P1 climb onto a taller neighbour (docs/BWS.md, "Frame-to-frame pixel noise"). The per-axis median of the P1s
/// of the last `frames` frames taken while nothing moved keeps one such frame from deciding. Pure: no LCM, no clock.

#include <optional>
#include <vector>

#include <Eigen/Core>

namespace bookgrasp {

/// The P1s of the last still frames and their median.
class P1Frames {
 public:
  /// `frames` >= 1: how many frames make a P1 (1 = the latest frame's, the paper's).
  explicit P1Frames(int frames);

  /// How many frames make a P1.
  int frames() const { return frames_; }
  /// Forgets every frame (the arm moved: the scene in view may have changed).
  void clear() { window_.clear(); }
  /// Adds a still frame's P1 (base), or std::nullopt when BwS found none in it; the oldest frame beyond `frames`
  /// is dropped.
  void add(const std::optional<Eigen::Vector3d>& p1);
  /// Frames held now (at most frames()).
  int size() const { return static_cast<int>(window_.size()); }
  /// There are `frames` frames: a P1 (or its absence) can be told.
  bool full() const { return size() >= frames_; }
  /// With full(): the per-axis median of the frames' P1s when more than half of them found one, else std::nullopt
  /// (BwS found nothing). Before full(): std::nullopt.
  std::optional<Eigen::Vector3d> p1() const;

 private:
  int frames_;
  std::vector<std::optional<Eigen::Vector3d>> window_;  ///< oldest first
};

}  // namespace bookgrasp
