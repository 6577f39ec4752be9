/// @file
/// bookgrasp_snapshot: renders the cameras of a scene + seed and writes the
/// pictures and the ground truth, for a person to look at.
///
///   bookgrasp_snapshot --scene FILE --seed S --out DIR
///
/// Writes left.png, right.png, hand.png (as the cameras publish them, with
/// noise and exposure), overlay.png (left image with the ground truth drawn),
/// depth.png (left camera depth, colour-mapped, range written on it) and
/// truth.json (SimModel::ground_truth(), every field).

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include "common/image_conversion.h"
#include "common/sim_render/sim_camera_rig.h"
#include "services/snapshot/truth_json.h"
#include "services/snapshot/truth_overlay.h"

namespace {

int usage(const char* why) {
  if (why) std::cerr << "bookgrasp_snapshot: " << why << "\n";
  std::cerr << "usage: bookgrasp_snapshot --scene FILE --seed S --out DIR\n"
               "  writes left.png right.png hand.png overlay.png depth.png truth.json into DIR\n";
  return why ? 2 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene_file, out_dir;
  long long seed = -1;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") return usage(nullptr);
    if (i + 1 >= argc) return usage((a + " needs a value").c_str());
    if (a == "--scene") {
      scene_file = argv[++i];
    } else if (a == "--seed") {
      char* end = nullptr;
      seed = std::strtoll(argv[++i], &end, 10);
      if (!end || *end != '\0' || seed < 0) return usage("--seed must be a non-negative integer");
    } else if (a == "--out") {
      out_dir = argv[++i];
    } else {
      return usage(("unknown argument " + a).c_str());
    }
  }
  if (scene_file.empty() || out_dir.empty() || seed < 0) return usage("--scene, --seed and --out are required");
  try {
    std::filesystem::create_directories(out_dir);
    bookgrasp::sim_render::SimCameraRig rig(scene_file, static_cast<uint64_t>(seed));
    const int64_t utime = 0;
    const auto left = rig.capture("stereo_left", utime, /*with_depth=*/true);
    const auto right = rig.capture("stereo_right", utime);
    const auto hand = rig.capture("hand_camera", utime);
    const bookgrasp::ground_truth_t truth = rig.model().ground_truth(utime);
    const auto path = [&](const char* name) { return (std::filesystem::path(out_dir) / name).string(); };
    bookgrasp::write_png(path("left.png"), left.rgb);
    bookgrasp::write_png(path("right.png"), right.rgb);
    bookgrasp::write_png(path("hand.png"), hand.rgb);
    bookgrasp::write_png(path("overlay.png"),
                         bookgrasp::snapshot::draw_ground_truth(left.rgb, truth, left.camera,
                                                                rig.scene().cart_marker.size_m,
                                                                rig.scene().holder_marker.size_m));
    bookgrasp::write_png(path("depth.png"), bookgrasp::snapshot::colorize_depth(left.depth));
    std::ofstream json(path("truth.json"));
    json << bookgrasp::snapshot::ground_truth_json(truth);
    if (!json) throw std::runtime_error("cannot write " + path("truth.json"));
    std::cout << "scene " << truth.scene << " seed " << seed << ": " << truth.num_books << " books\n";
    for (const char* f : {"left.png", "right.png", "hand.png", "overlay.png", "depth.png", "truth.json"}) {
      std::cout << "wrote " << path(f) << "\n";
    }
  } catch (const std::exception& e) {
    std::cerr << "bookgrasp_snapshot: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
