/// @file
/// bookgrasp_eval_segmentation: Hoover et al. 1996 comparison of the planar segmentations (GoD, PCL,
/// jump components) on simulator range images with per-surface ground truth.
///
///   bookgrasp_eval_segmentation --out DIR [--scenes N] [--seed S] [--scene FILE] [--no-curved]
///                               [--no-stereo] [--noise PX] [--pictures K] [--god-config FILE]
///                               [--pcl-config FILE] [--min-gt-px P] [--stereo-algorithm bm|sgbm]
///                               [--verbose]
///
/// Scenes S..S+N-1 (defaults 20 and 1) of FILE (default config/scenes/default.yaml) with a cup and a
/// ball added on the upper shelf (unless --no-curved). Writes DIR/metrics.json, DIR/report.md and
/// DIR/scene_<seed>.png for the first K scenes (default 3). Progress on stderr.

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#include "common/image_conversion.h"
#include "common/version.h"
#include "services/eval_segmentation/segmentation_eval.h"

namespace {

int usage(const std::string& why) {
  if (!why.empty()) std::cerr << "bookgrasp_eval_segmentation: " << why << "\n";
  std::cerr << "usage: bookgrasp_eval_segmentation --out DIR [--scenes N] [--seed S] [--scene FILE] [--no-curved]\n"
               "                                   [--no-stereo] [--noise PX] [--pictures K] [--god-config FILE]\n"
               "                                   [--pcl-config FILE] [--min-gt-px P] [--stereo-algorithm bm|sgbm]\n"
               "                                   [--steep-curvature PX] [--verbose]\n"
               "  renders scenes S..S+N-1 (default 20 scenes from seed 1) with ground-truth surfaces, runs GoD,\n"
               "  PCL and jump components on the true-depth and the StereoBM disparity, compares them by Hoover's\n"
               "  metric at T = 0.5..0.9 (GT regions >= P px, default 100; StereoBM as configured, or SGBM); writes "
               "DIR/metrics.json, DIR/report.md, DIR/scene_<seed>.png\n"
               "  --steep-curvature PX: the method god_steep is GoD with god.jump_min_curvature PX (default 0.6;\n"
               "  0 = no god_steep)\n";
  return why.empty() ? 0 : 2;
}

std::string in_source(const std::string& p) {
  if (std::filesystem::path(p).is_absolute() || std::filesystem::exists(p)) return p;
  return (std::filesystem::path(bookgrasp::kSourceDir) / p).string();
}

}  // namespace

int main(int argc, char** argv) {
  using namespace bookgrasp::eval_segmentation;
  long long scenes = 20, seed = 1, pictures = 3, min_gt_px = 100;
  std::string stereo_algorithm = "bm";
  bool curved = true, stereo = true, verbose = false;
  double noise = 0.1, steep_curvature = 0.6;
  std::string scene_file = "config/scenes/default.yaml", out_dir;
  std::string god_config = "config/services/bws_detector.yaml", pcl_config = "config/services/bws_detector_pcl.yaml";
  std::string command = "bookgrasp_eval_segmentation";
  for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") return usage("");
    if (a == "--no-curved") {
      curved = false;
      continue;
    }
    if (a == "--verbose") {
      verbose = true;
      continue;
    }
    if (a == "--no-stereo") {
      stereo = false;
      continue;
    }
    if (i + 1 >= argc) return usage(a + " needs a value");
    const std::string v = argv[++i];
    const auto integer = [&](long long* dst) {
      char* end = nullptr;
      *dst = std::strtoll(v.c_str(), &end, 10);
      return !v.empty() && end && *end == '\0' && *dst >= 0;
    };
    if (a == "--scenes") {
      if (!integer(&scenes) || scenes < 1) return usage("--scenes must be a positive integer, not '" + v + "'");
    } else if (a == "--seed") {
      if (!integer(&seed)) return usage("--seed must be a non-negative integer, not '" + v + "'");
    } else if (a == "--pictures") {
      if (!integer(&pictures)) return usage("--pictures must be a non-negative integer, not '" + v + "'");
    } else if (a == "--min-gt-px") {
      if (!integer(&min_gt_px) || min_gt_px < 1)
        return usage("--min-gt-px must be a positive integer, not '" + v + "'");
    } else if (a == "--stereo-algorithm") {
      stereo_algorithm = v;
      if (v != "bm" && v != "sgbm") return usage("--stereo-algorithm must be bm or sgbm, not '" + v + "'");
    } else if (a == "--noise") {
      char* end = nullptr;
      noise = std::strtod(v.c_str(), &end);
      if (v.empty() || !end || *end != '\0' || !(noise >= 0)) return usage("--noise must be a number >= 0 (pixels)");
    } else if (a == "--steep-curvature") {
      char* end = nullptr;
      steep_curvature = std::strtod(v.c_str(), &end);
      if (v.empty() || !end || *end != '\0' || !(steep_curvature >= 0) || !std::isfinite(steep_curvature))
        return usage("--steep-curvature must be a number >= 0 (disparity pixels), not '" + v + "'");
    } else if (a == "--scene") {
      scene_file = v;
    } else if (a == "--god-config") {
      god_config = v;
    } else if (a == "--pcl-config") {
      pcl_config = v;
    } else if (a == "--out") {
      out_dir = v;
    } else {
      return usage("unknown argument " + a);
    }
  }
  if (out_dir.empty()) return usage("--out DIR is required");
  try {
    scene_file = in_source(scene_file);
    EvalConfig config = EvalConfig::from_files(in_source(god_config), in_source(pcl_config));
    config.true_noise_px = noise;
    config.steep_curvature = steep_curvature;
    config.stereo = stereo;
    if (stereo_algorithm == "sgbm") config.god.disparity.algorithm = bookgrasp::bws::StereoAlgorithm::kSemiGlobal;
    std::filesystem::create_directories(out_dir);
    const auto path = [&](const std::string& name) { return (std::filesystem::path(out_dir) / name).string(); };
    std::vector<SceneEval> results;
    for (long long k = 0; k < scenes; ++k) {
      const uint64_t s = uint64_t(seed + k);
      RangeSceneOptions o;
      o.scene_file = scene_file;
      o.seed = s;
      o.curved_objects = curved;
      o.min_region_px = int(min_gt_px);
      // No disparity in the left num_disparities columns (block matching): not ground truth for either source.
      o.left_margin_px = config.god.disparity.num_disparities;
      const RangeScene scene = render_range_scene(o);
      results.push_back(evaluate_scene(scene, s, config));
      const SceneEval& e = results.back();
      if (k < pictures) bookgrasp::write_png(path("scene_" + std::to_string(s) + ".png"), scene_picture(scene, e));
      std::cerr << "[" << (k + 1) << "/" << scenes << "] seed " << s << ": " << e.gt_regions << " GT regions ("
                << e.curved_gt_regions << " curved)";
      for (const MethodRun& r : e.runs) {
        for (size_t i = 0; i < config.tolerances.size(); ++i)
          if (std::abs(config.tolerances[i] - 0.8) < 1e-9)
            std::cerr << ", " << r.name << " " << r.hoover[i].correct << " correct";
      }
      std::cerr << std::endl;
      if (verbose) {  // every GT region with its class per method at T = 0.8
        for (const GtRegion& g : scene.regions) {
          std::cerr << "  GT " << g.label << " " << g.name << " " << g.pixel_count << " px"
                    << (g.planar ? "" : " curved");
          for (const MethodRun& r : e.runs)
            for (const HooverResult& h : r.hoover)
              if (std::abs(h.tolerance - 0.8) < 1e-9)
                std::cerr << " " << r.name << ":" << hoover_class_name(h.gt_class_of(g.label));
          std::cerr << "\n";
        }
      }
    }
    std::ofstream(path("metrics.json")) << metrics_json(results, config, scene_file, uint64_t(seed), curved);
    const std::string report = report_markdown(results, config, command, curved);
    std::ofstream(path("report.md")) << report;
    std::cout << report << "wrote " << path("metrics.json") << ", report.md and " << std::min(pictures, scenes)
              << " scene pictures\n";
  } catch (const std::exception& e) {
    std::cerr << "bookgrasp_eval_segmentation: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
