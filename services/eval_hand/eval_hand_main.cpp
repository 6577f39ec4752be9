/// @file
/// bookgrasp_eval_hand: the hand-camera evaluation (issue 5, paper Figures 13 and 14).
///
///   bookgrasp_eval_hand --scenes N --seed S [--scene FILE] [--config-dir DIR] [--no-markers]
///                       [--debug-images] [--debug-every K] --out DIR
///
/// For scenes S..S+N-1 of FILE (default services/eval_hand/scenes/hand_eval.yaml) the visual servo is closed
/// in simulation (hand_servo_harness.h): the stripe servo from station A (PS vs the true stripe end) and the
/// corner servo from a seeded start offset of up to 5 cm around the true P1 (P2 and the slope vs the truth);
/// the marker detector is timed on each scene's stereo left image. Writes DIR/metrics.json, DIR/report.md,
/// DIR/figure13_p2_error.png, DIR/figure14_stripe_end.png, DIR/slope_error.png; progress on stderr.
/// Exit status 0 when the tool ran (failed scenes are results, listed in metrics.json), 2 on bad arguments.

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "common/version.h"
#include "services/eval_hand/hand_eval_metrics.h"
#include "services/eval_hand/hand_scene_eval.h"

namespace {

int usage(const std::string& why) {
  if (!why.empty()) std::cerr << "bookgrasp_eval_hand: " << why << "\n";
  std::cerr << "usage: bookgrasp_eval_hand --scenes N --seed S [--scene FILE] [--config-dir DIR] [--no-markers]\n"
               "                           [--debug-images] [--debug-every K] --out DIR\n"
               "  closes the stripe and corner servos in simulation on scenes S..S+N-1 (default scene\n"
               "  services/eval_hand/scenes/hand_eval.yaml), errors against the simulation's ground truth;\n"
               "  writes DIR/metrics.json, DIR/report.md and the PNG plots (Figures 13 and 14);\n"
               "  --debug-images: first/last hand image of each task in DIR/images (overlay and raw),\n"
               "  --debug-every K: also every K-th frame\n";
  return why.empty() ? 0 : 2;
}

std::string in_source(const std::string& p) {
  return std::filesystem::path(p).is_absolute() ? p : (std::filesystem::path(bookgrasp::kSourceDir) / p).string();
}

}  // namespace

int main(int argc, char** argv) {
  long long scenes = -1, seed = -1;
  bool markers = true, debug_images = false;
  int debug_every = 0;
  std::string scene_file = "services/eval_hand/scenes/hand_eval.yaml", config_dir = "config/services", out_dir;
  std::string command = "bookgrasp_eval_hand";
  for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") return usage("");
    if (a == "--no-markers") {
      markers = false;
      continue;
    }
    if (a == "--debug-images") {
      debug_images = true;
      continue;
    }
    if (a != "--scenes" && a != "--seed" && a != "--scene" && a != "--config-dir" && a != "--out" &&
        a != "--debug-every")
      return usage("unknown option " + a);
    if (i + 1 >= argc) return usage(a + " needs a value");
    const std::string v = argv[++i];
    const auto integer = [&](long long* dst) {
      char* end = nullptr;
      *dst = std::strtoll(v.c_str(), &end, 10);
      return end && end != v.c_str() && *end == '\0' && *dst >= 0;
    };
    if (a == "--scenes") {
      if (!integer(&scenes) || scenes < 1) return usage("--scenes must be a positive integer, not '" + v + "'");
    } else if (a == "--seed") {
      if (!integer(&seed)) return usage("--seed must be a non-negative integer, not '" + v + "'");
    } else if (a == "--scene") {
      scene_file = v;
    } else if (a == "--debug-every") {
      long long n = 0;
      if (!integer(&n) || n < 1) return usage("--debug-every must be a positive integer, not '" + v + "'");
      debug_every = static_cast<int>(n);
    } else if (a == "--config-dir") {
      config_dir = v;
    } else {
      out_dir = v;
    }
  }
  if (scenes < 0) return usage("--scenes is required");
  if (seed < 0) return usage("--seed is required");
  if (out_dir.empty()) return usage("--out is required");
  bookgrasp::HandSceneSettings settings;
  settings.scene_file = in_source(scene_file);
  settings.config_dir = in_source(config_dir);
  settings.run_markers = markers;
  if (!std::filesystem::is_regular_file(settings.scene_file))
    return usage("scene file not found: " + settings.scene_file);
  if (!std::filesystem::is_directory(settings.config_dir))
    return usage("config folder not found: " + settings.config_dir);
  try {
    std::filesystem::create_directories(out_dir);
  } catch (const std::exception& e) {
    return usage("cannot create --out " + out_dir + ": " + e.what());
  }
  if (debug_images || debug_every > 0) settings.debug_image_dir = (std::filesystem::path(out_dir) / "images").string();
  settings.debug_every_frames = debug_every;

  const bookgrasp::HandTolerances tol;
  bookgrasp::HandEvalMetrics m;
  std::vector<bookgrasp::HandSceneOutcome> outcomes;
  const std::string metrics_path = (std::filesystem::path(out_dir) / "metrics.json").string();
  for (long long k = 0; k < scenes; ++k) {
    const uint64_t s = static_cast<uint64_t>(seed + k);
    outcomes.push_back(bookgrasp::evaluate_hand_scene(s, settings));
    const auto& o = outcomes.back();
    bookgrasp::accumulate(o, tol, &m);
    std::cerr << "[" << (k + 1) << "/" << scenes << "] seed " << s << ": stripe " << o.stripe.state;
    if (o.stripe.converged) std::cerr << " (" << o.stripe.error_x_m * 1e3 << ", " << o.stripe.error_y_m * 1e3 << ") mm";
    std::cerr << ", corner " << o.corner.state;
    if (o.corner.converged) std::cerr << " (" << o.corner.error_x_m * 1e3 << ", " << o.corner.error_y_m * 1e3 << ") mm";
    if (!o.error.empty()) std::cerr << ", ERROR " << o.error;
    std::cerr << ", " << o.wall_s << " s; failed scenes so far " << m.failed_scenes << std::endl;
    // metrics.json after every scene and the report every 10, so a long run can be stopped and still be read.
    std::ofstream(metrics_path) << bookgrasp::hand_metrics_json(m, command, outcomes);
    if ((k + 1) % 10 == 0 && k + 1 < scenes) {
      try {
        bookgrasp::write_hand_report(out_dir, m, outcomes, tol,
                                     command + "  (partial: " + std::to_string(k + 1) + " scenes)");
      } catch (const std::exception& e) {
        std::cerr << "bookgrasp_eval_hand: " << e.what() << "\n";
      }
    }
  }
  try {
    bookgrasp::write_hand_report(out_dir, m, outcomes, tol, command);
  } catch (const std::exception& e) {
    std::cerr << "bookgrasp_eval_hand: " << e.what() << "\n";
    return 1;
  }
  std::cerr << "wrote " << metrics_path << ", report.md and the plots in " << out_dir << "\n";
  return 0;
}
