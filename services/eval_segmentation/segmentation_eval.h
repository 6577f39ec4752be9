#pragma once
/// @file
/// The segmentation comparison of issue 4 item 5: on every range scene (range_scene.h) the planar
/// segmentations of bws_detector -- GoD (services/bws_detector/god_segmentation.h, parameters of
/// config/services/bws_detector.yaml), the PCL implementation's OrganizedMultiPlaneSegmentation
/// (config/services/bws_detector_pcl.yaml), the jump-free connected components baseline, and PCL's region
/// growing on normals ("rg", pcl_region_growing.h) -- are run
/// on two disparity sources and compared with the ground truth by Hoover's metric at several
/// tolerances:
///   - "true": the renderer's exact depth turned into disparity d = fx B / z, plus zero-mean Gaussian
///     noise (`true_noise_px`) and rounding to StereoBM's 1/16 px (the simulated camera has an image
///     noise model only, so this range-sensor noise is ours);
///   - "stereo": the bws_detector's disparity (StereoBM, its configured parameters) on the rendered
///     stereo pair through the cameras' sensor model, as the running detector sees it.
/// Then the statistics (metrics.json, report.md) and a picture per scene.

#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "services/bws_detector/baseline_segmentation.h"
#include "services/bws_detector/bws_pipeline.h"
#include "services/eval_segmentation/hoover_comparison.h"
#include "services/eval_segmentation/pcl_region_growing.h"
#include "services/eval_segmentation/range_scene.h"

namespace bookgrasp::eval_segmentation {

/// Everything the comparison is configured with.
struct EvalConfig {
  /// GoD parameters and the disparity parameters (bws_detector.yaml).
  bws::BwsParams god;
  /// PCL parameters (bws_detector_pcl.yaml).
  bws::BwsParams pcl;
  /// Jump-components baseline (its defaults: max jump 0.5 disparity px, regions >= 50 px).
  bws::JumpComponentsParams jump;
  /// Region growing on normals (pcl::RegionGrowing, like Hoover's USF), its defaults (the PCL tutorial's values).
  RegionGrowingParams region_growing;
  /// > 0: also the method `god_steep`, the GoD above with god.jump_min_curvature at this value (jump edges must
  /// bend the disparity; steep planes, e.g. surfaces at a grazing angle, keep their direction). 0: no such method.
  double steep_curvature = 0.6;
  /// Noise of the "true" source, disparity pixels (standard deviation).
  double true_noise_px = 0.1;
  /// Rounding step of the "true" source, disparity pixels (StereoBM: 1/16).
  double disparity_quantum_px = 1.0 / 16.0;
  /// Also evaluate the StereoBM source.
  bool stereo = true;
  /// Hoover tolerances; 0.5 is evaluated as 0.5 + 1e-6 (Hoover's T must exceed 0.5).
  std::vector<double> tolerances = {0.5, 0.6, 0.7, 0.8, 0.9};

  /// Reads the GoD and PCL service configurations (paths absolute or relative to the working dir).
  static EvalConfig from_files(const std::string& god_config, const std::string& pcl_config);
};

/// The tolerance actually used for a nominal one (0.5 -> 0.500001, others unchanged).
double effective_tolerance(double nominal);

/// Key of a tolerance in metrics.json: "T0.5", "T0.8"...
std::string tolerance_key(double nominal);

/// Disparity from exact depth: fx * baseline / z + N(0, noise_px), rounded to `quantum_px` (0 = no
/// rounding); NaN where the depth is NaN or <= 0. Seeded: same inputs, same output.
cv::Mat true_disparity(const cv::Mat& depth, double fx, double baseline_m, double noise_px, double quantum_px,
                       uint64_t seed);

/// One method's segmentation of one source.
struct MethodRun {
  /// "god", "pcl", "jump", "rg" (true source) or "god_stereo", ... (stereo source).
  std::string name;
  /// CV_32S labels, 0 = no region.
  cv::Mat labels;
  /// Wall time of the segmentation, ms (not reproducible).
  double ms = 0.0;
  /// Hoover result per tolerance (order of EvalConfig::tolerances).
  std::vector<HooverResult> hoover;
};

/// Everything about one scene.
struct SceneEval {
  /// Seed.
  uint64_t seed = 0;
  /// GT regions, and how many of them are curved surfaces.
  int gt_regions = 0, curved_gt_regions = 0;
  /// Curved objects placed.
  int curved_objects_placed = 0;
  /// Disparities of the two sources (CV_32F, NaN = invalid); stereo empty if not evaluated.
  cv::Mat disparity_true, disparity_stereo;
  /// Fraction of GT-labelled pixels with a valid stereo disparity.
  double stereo_coverage = 0.0;
  /// Median |stereo - exact disparity| over those pixels, px (NaN if none): checks the stereo path.
  double stereo_median_error_px = 0.0;
  /// Method runs (true source first, then stereo).
  std::vector<MethodRun> runs;
  /// GT label of the right-most book's front (0 if not a GT region).
  int rightmost_front_label = 0;
  /// Category (GtCategory) of every GT region, index label - 1.
  std::vector<int> gt_category;
};

/// Kinds of ground-truth regions, for the breakdown of the results.
enum GtCategory : int {
  /// A book's fore-edge (front) face.
  kBookFront = 0,
  /// Any other face of a book (sides, top).
  kBookOther = 1,
  /// A curved surface (cup mantle, ball, robot mesh).
  kCurved = 2,
  /// Every other planar surface (cart boards, holder, screen, floor, walls, cup top).
  kOtherPlanar = 3,
  /// Number of categories.
  kNumCategories = 4,
};

/// Name of a category: "book_front", "book_other", "curved", "other_planar".
const char* gt_category_name(int category);

/// Category of a ground-truth region.
int gt_category_of(const GtRegion& region);

/// Runs every method on both sources of `scene` and compares with its ground truth.
SceneEval evaluate_scene(const RangeScene& scene, uint64_t seed, const EvalConfig& config);

/// Sum over scenes, per method: totals per tolerance, median ms, right-most fronts detected at T = 0.8.
struct MethodSummary {
  /// Method name.
  std::string name;
  /// Totals per tolerance.
  std::vector<HooverTotals> totals;
  /// Median segmentation wall time, ms.
  double median_ms = 0.0;
  /// Scenes where the right-most book's front (a GT region) is a correct detection at T = 0.8.
  int rightmost_front_correct = 0;
  /// Scenes where the right-most book's front is a GT region.
  int rightmost_front_scenes = 0;
  /// GT regions per category and those correctly detected at T = 0.8.
  std::vector<long long> category_regions = std::vector<long long>(kNumCategories, 0),
                         category_correct = std::vector<long long>(kNumCategories, 0);
};

/// Summaries of every method (in the order of the runs).
std::vector<MethodSummary> summarize(const std::vector<SceneEval>& scenes, const EvalConfig& config);

/// metrics.json text: methods.<name>.T<tol>.{correct,over,under,missed,noise} (fractions: the first four of
/// GT regions, noise of machine regions) plus counts, sources, the paper's Table 1 and settings.
std::string metrics_json(const std::vector<SceneEval>& scenes, const EvalConfig& config, const std::string& scene_file,
                         uint64_t first_seed, bool curved_objects);

/// report.md text: tables like the paper's Table 1 (paper's numbers beside ours) per source, all classes at
/// T = 0.8, the command.
std::string report_markdown(const std::vector<SceneEval>& scenes, const EvalConfig& config, const std::string& command,
                            bool curved_objects);

/// Picture of one scene (CV_8UC3 RGB): left image and ground truth, each method's labels per source,
/// titles with the T = 0.8 counts.
cv::Mat scene_picture(const RangeScene& scene, const SceneEval& eval);

}  // namespace bookgrasp::eval_segmentation
