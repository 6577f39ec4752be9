/// @file
/// bookgrasp_eval_bws: BwS accuracy and timing over seeded random simulated scenes.
///
///   bookgrasp_eval_bws --scenes N --seed S [--scene FILE] [--impl god|pcl] [--config FILE]
///                      [--overlays K] [--marker-config FILE] [--first-utime U] --out DIR
///
/// Scenes S..S+N-1 of FILE (default config/scenes/default.yaml) are rendered by the simulator; the
/// cart marker is found by the marker detector (config/services/marker_detector.yaml) and the
/// bws_detector component (config/services/bws_detector.yaml, or bws_detector_pcl.yaml for --impl pcl)
/// answers the stereo frame. Writes DIR/metrics.json, DIR/report.md, DIR/figure12.png and overlay PNGs
/// (overlay_<seed>.png) of the first K scenes (default 5) and of every failed scene. The frame is stamped U
/// (default 1000000); the simulated camera's pixel noise is seeded by it, so another U gives the same scenes
/// with other noise (how much P1 moves from frame to frame: docs/BWS.md, stop 40).

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "common/config.h"
#include "common/image_conversion.h"
#include "common/sim_render/sim_camera_rig.h"
#include "common/version.h"
#include "services/bws_detector/bws_detector_node.h"
#include "services/eval_bws/bws_scene_eval.h"
#include "services/marker_detector/marker_detector_node.h"

namespace {

int usage(const std::string& why) {
  if (!why.empty()) std::cerr << "bookgrasp_eval_bws: " << why << "\n";
  std::cerr
      << "usage: bookgrasp_eval_bws --scenes N --seed S [--scene FILE] [--impl god|pcl] [--config FILE]\n"
         "                          [--overlays K] [--marker-config FILE] [--first-utime U] [--verbose] --out DIR\n"
         "  renders scenes S..S+N-1, runs the marker detector and the bws_detector on each stereo pair,\n"
         "  writes DIR/metrics.json, DIR/report.md, DIR/figure12.png, overlay_<seed>.png\n"
         "  --first-utime U stamps each frame U (default 1000000): the pixel noise is seeded by it, so another\n"
         "  U gives the same scenes with other noise\n";
  return why.empty() ? 0 : 2;
}

std::string in_source(const std::string& p) {
  return std::filesystem::path(p).is_absolute() ? p : (std::filesystem::path(bookgrasp::kSourceDir) / p).string();
}

}  // namespace

int main(int argc, char** argv) {
  long long scenes = -1, seed = -1, overlays = 5, first_utime = 1000000;
  bool verbose = false;
  std::string scene_file = "config/scenes/default.yaml", impl = "god", config_file, out_dir;
  std::string marker_config = "config/services/marker_detector.yaml";
  std::string command = "bookgrasp_eval_bws";
  for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") return usage("");
    if (a == "--verbose") {
      verbose = true;
      continue;
    }
    if (i + 1 >= argc) return usage(a + " needs a value");
    const std::string v = argv[++i];
    const auto integer = [&](long long* dst) {
      char* end = nullptr;
      *dst = std::strtoll(v.c_str(), &end, 10);
      return end && *end == '\0' && *dst >= 0;
    };
    if (a == "--scenes") {
      if (!integer(&scenes) || scenes < 1) return usage("--scenes must be a positive integer");
    } else if (a == "--seed") {
      if (!integer(&seed)) return usage("--seed must be a non-negative integer");
    } else if (a == "--overlays") {
      if (!integer(&overlays)) return usage("--overlays must be a non-negative integer");
    } else if (a == "--first-utime") {
      if (!integer(&first_utime)) return usage("--first-utime must be a non-negative integer");
    } else if (a == "--scene") {
      scene_file = v;
    } else if (a == "--impl") {
      impl = v;
      if (impl != "god" && impl != "pcl") return usage("--impl must be god or pcl");
    } else if (a == "--config") {
      config_file = v;
    } else if (a == "--marker-config") {
      marker_config = v;
    } else if (a == "--out") {
      out_dir = v;
    } else {
      return usage("unknown argument " + a);
    }
  }
  if (scenes < 1 || seed < 0 || out_dir.empty()) return usage("--scenes, --seed and --out are required");
  if (config_file.empty())
    config_file =
        in_source(impl == "god" ? "config/services/bws_detector.yaml" : "config/services/bws_detector_pcl.yaml");
  if (!std::filesystem::exists(scene_file)) scene_file = in_source(scene_file);

  try {
    std::filesystem::create_directories(out_dir);
    const bookgrasp::Config bws_root = bookgrasp::Config::load_file(config_file);
    bookgrasp::BwsDetectorSettings bws_settings = bookgrasp::BwsDetectorSettings::from_config(bws_root);
    if (bws_settings.params.implementation != impl)
      throw std::runtime_error(config_file + " is for implementation '" + bws_settings.params.implementation +
                               "', not --impl " + impl);
    bws_settings.measure_processing_time = true;
    const bookgrasp::Config md_root = bookgrasp::Config::load_file(in_source(marker_config));
    const auto md_settings = bookgrasp::MarkerDetectorSettings::from_config(md_root);

    std::vector<bookgrasp::eval_bws::SceneResult> results;
    const auto path = [&](const std::string& name) { return (std::filesystem::path(out_dir) / name).string(); };
    for (long long k = 0; k < scenes; ++k) {
      const uint64_t s = uint64_t(seed + k);
      // Fresh components per scene: no marker carried over from another scene.
      bookgrasp::MarkerDetectorNode markers(md_settings);
      bookgrasp::BwsDetectorNode bws(bws_settings);
      bookgrasp::sim_render::SimCameraRig rig(scene_file, s);
      const auto rendered = bookgrasp::eval_bws::render_scene(rig, first_utime);
      cv::Mat overlay;
      results.push_back(bookgrasp::eval_bws::evaluate_scene(rendered, s, markers, bws, &overlay));
      const auto& r = results.back();
      if (verbose) {
        const auto& o = bws.last_output();
        std::cerr << "\nseed " << s << ": " << (r.failure.empty() ? "ok" : r.failure) << "\n";
        for (const auto& v : o.selection.regions) {
          if (v.reason.rfind("too small", 0) == 0 ||
              (v.reason.rfind("not parallel", 0) == 0 && v.inside_fraction < 0.5))
            continue;
          const auto& pr = o.segmentation.regions[size_t(v.label - 1)];
          std::cerr << "  region " << v.label << " px " << pr.pixel_count << " bbox " << pr.bbox << " inside "
                    << v.inside_fraction << " w " << v.width_m << " h " << v.height_m << " n_base "
                    << v.normal_base.transpose() << " : " << (v.candidate ? "CANDIDATE " : "") << v.reason << "\n";
          if (!v.bands.empty()) std::cerr << "    bands: " << v.bands << "\n";
        }
      }
      if ((k < overlays || !r.found || r.wrong_book) && !overlay.empty())
        bookgrasp::write_png(path("overlay_" + std::to_string(s) + ".png"), overlay);
      int failed = 0;
      for (const auto& q : results) failed += (!q.found || q.wrong_book);
      const int bar = 30, done = int((k + 1) * bar / scenes);
      std::cerr << "\r[" << std::string(size_t(done), '#') << std::string(size_t(bar - done), '.') << "] " << (k + 1)
                << "/" << scenes << " seed " << s << " failures " << failed << "   " << std::flush;
    }
    std::cerr << "\n";
    std::ofstream(path("metrics.json")) << bookgrasp::eval_bws::metrics_json(results, impl, scene_file, uint64_t(seed));
    std::ofstream(path("report.md")) << bookgrasp::eval_bws::report_markdown(results, impl, command);
    bookgrasp::write_png(path("figure12.png"),
                         bookgrasp::eval_bws::figure12_plot(
                             results, "BwS (" + impl + "): |P1 error| in the grasp frame per scene, seeds " +
                                          std::to_string(seed) + ".." + std::to_string(seed + scenes - 1)));
    std::cout << bookgrasp::eval_bws::report_markdown(results, impl, command);
    std::cout << "wrote " << path("metrics.json") << ", report.md, figure12.png\n";
  } catch (const std::exception& e) {
    std::cerr << "\nbookgrasp_eval_bws: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
