/// @file
/// bookgrasp_eval_full: N seeded scenes through the whole library cycle composed in one process
/// (full_cycle_harness.h), physics deciding whether each grasp worked. Writes DIR/metrics.json,
/// DIR/report.md with PNG plots (paper Section 5), DIR/scenes.csv, and the failures with their seeds.
/// Every scene is also kept in DIR/scenes/seed_<S>.yaml (scene_record.h): --resume continues a stopped run,
/// --merge joins runs over different seed ranges into one report.

#include <unistd.h>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "common/config.h"
#include "services/eval_full/eval_report.h"
#include "services/eval_full/full_cycle_harness.h"
#include "services/eval_full/full_cycle_metrics.h"
#include "services/eval_full/scene_record.h"

namespace {

void usage(std::ostream& os) {
  os << "usage: bookgrasp_eval_full --scenes N --seed S --out DIR [options]\n"
        "  N seeded scenes (seeds S, S+1, ..., S+N-1) through the whole library cycle in one process.\n"
        "  --scene FILE       scene YAML (default: the one in config/services/sim_world.yaml)\n"
        "  --books K          books per scene before moving on (default 1; 0 = until the upper shelf is empty)\n"
        "  --budget-s B       simulation-time budget per scene, s (default 240 per book, 3600 for --books 0)\n"
        "  --done-after-s D   the coordinator's own \"done\" after D s in WAIT_USER (default 1)\n"
        "  --stereo-hz R      stereo camera frame rate (default: stereo_camera.yaml)\n"
        "  --hand-hz R        hand camera frame rate (default: hand_camera.yaml)\n"
        "  --log              record each scene's bus (no images) to DIR/logs/seed_<S>.lcmlog\n"
        "  --log-channels A,B,...  with --log: record only these channels (e.g. the arbiter's, for a replay sample)\n"
        "  --log-images       with --log: also record STEREO_IMAGES, HAND_IMAGE and BWS_DEBUG_IMAGE (large), to\n"
        "                     replay a detector on the cycle's own frames\n"
        "  --snapshots        PNGs of the hand/stereo images (with what was detected, and the hand image raw) at\n"
        "                     every state change in DIR/snapshots/seed_<S>/\n"
        "  --snapshot-period-s P  with --snapshots: also a hand image every P s while a servo runs\n"
        "  --verbose          print the TASK_STATUS / GRASP_POINT trace\n"
        "  --set S:KEY=VALUE  override a configuration value of service S (e.g. "
        "marker_detector:apriltag.quad_decimate=1)\n"
        "  --source-dir DIR   project tree (default: the one this tool was built from)\n"
        "  --resume           keep the scenes DIR/scenes/ already holds (same options) and run only the others\n"
        "Re-run one failed scene alone: --scenes 1 --seed <its seed>.\n"
        "\n"
        "usage: bookgrasp_eval_full --merge DIR1,DIR2,... --out DIR\n"
        "  One report (metrics.json, scenes.csv, report.md) over the scenes of runs with the same options over\n"
        "  different seeds; the figures are those of one run over all of them.\n";
}

/// "A,B,C" -> {A, B, C} (empty items dropped).
std::vector<std::string> comma_list(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream list(text);
  for (std::string c; std::getline(list, c, ',');)
    if (!c.empty()) out.push_back(c);
  return out;
}

/// --log-channels' list; throws when it names no channel.
std::vector<std::string> channel_list(const std::string& text) {
  std::vector<std::string> out = comma_list(text);
  if (out.empty()) throw std::invalid_argument("--log-channels needs at least one channel name");
  return out;
}

/// Writes DIR/scenes.csv from `rows` (by seed).
void write_csv(const std::string& dir, const std::map<uint64_t, std::string>& rows) {
  std::ofstream csv(dir + "/scenes.csv");
  csv << "seed,end,books_on_upper_shelf,books_moved,grasp_attempts,grasp_successes,sim_s,wall_s,failure\n";
  for (const auto& [seed, row] : rows) csv << row << "\n";
}

/// --merge: the scenes of `dirs` in one report in `out`. Returns the exit code.
int merge_runs(const std::vector<std::string>& dirs, const std::string& out, const std::string& command) {
  using namespace bookgrasp;
  std::map<uint64_t, SceneRecord> all;
  try {
    all = merged_scene_records(dirs);
  } catch (const std::exception& e) {
    std::cerr << "bookgrasp_eval_full: --merge: " << e.what() << "\n";
    return 2;
  }
  EvalMetrics metrics;
  std::map<uint64_t, std::string> rows;
  for (const auto& [seed, r] : all) {
    add_metrics(r.metrics, &metrics);
    rows[seed] = r.csv_row;
  }
  std::filesystem::create_directories(out);
  write_csv(out, rows);
  const std::string described = command + " (" + std::to_string(all.size()) + " scenes, seeds " +
                                std::to_string(all.begin()->first) + ".." + std::to_string(all.rbegin()->first) +
                                "; options: " + all.begin()->second.options + ")";
  std::ofstream(out + "/metrics.json") << metrics_json(metrics, described);
  write_report(out, metrics, described, all.begin()->second.books_per_scene);
  std::cout << metrics_json(metrics, described);
  std::cout << "report: " << out << "/report.md\n";
  return 0;
}

std::string progress_bar(int done, int total, double eta_s, int failures) {
  const int w = 30;
  const int fill = total > 0 ? done * w / total : w;
  std::string bar(fill, '#');
  bar += std::string(w - fill, '.');
  char b[160];
  std::snprintf(b, sizeof b, "\r[%s] %d/%d scenes, %d failed, ETA %.0f s   ", bar.c_str(), done, total, failures,
                eta_s);
  return b;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace bookgrasp;
  int scenes = -1, books = 1;
  long long seed = -1;
  double snapshot_period = 0;
  double budget = -1, done_after = 1.0, stereo_hz = 0, hand_hz = 0;
  std::string out, scene_file, source_dir = BOOKGRASP_SOURCE_DIR;
  bool log = false, log_images = false, snapshots = false, verbose = false, resume = false;
  std::vector<std::string> merge;
  std::vector<std::string> overrides, log_channels;
  std::ostringstream cmd;
  cmd << "bookgrasp_eval_full";
  for (int i = 1; i < argc; ++i) cmd << " " << argv[i];
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
        return argv[++i];
      };
      if (a == "--help" || a == "-h") {
        usage(std::cout);
        return 0;
      } else if (a == "--scenes") scenes = std::stoi(value());
      else if (a == "--seed") seed = std::stoll(value());
      else if (a == "--out") out = value();
      else if (a == "--scene") scene_file = value();
      else if (a == "--books") books = std::stoi(value());
      else if (a == "--budget-s") budget = std::stod(value());
      else if (a == "--done-after-s") done_after = std::stod(value());
      else if (a == "--stereo-hz") stereo_hz = std::stod(value());
      else if (a == "--hand-hz") hand_hz = std::stod(value());
      else if (a == "--source-dir") source_dir = value();
      else if (a == "--set") overrides.push_back(value());
      else if (a == "--log") log = true;
      else if (a == "--log-images")
        log_images = true;
      else if (a == "--log-channels")
        log_channels = channel_list(value());
      else if (a == "--snapshots") snapshots = true;
      else if (a == "--snapshot-period-s") snapshot_period = std::stod(value());
      else if (a == "--verbose") verbose = true;
      else if (a == "--resume")
        resume = true;
      else if (a == "--merge") {
        merge = comma_list(value());
        if (merge.empty()) throw std::invalid_argument("--merge needs at least one directory");
      } else
        throw std::invalid_argument("unknown argument " + a);
    }
    if (!merge.empty()) {
      if (out.empty()) throw std::invalid_argument("--merge needs --out DIR");
    } else if (scenes < 1)
      throw std::invalid_argument("--scenes N (>= 1) is required");
    if (merge.empty() && seed < 0) throw std::invalid_argument("--seed S (>= 0) is required");
    if (out.empty()) throw std::invalid_argument("--out DIR is required");
    if (books < 0) throw std::invalid_argument("--books must be >= 0");
    if (log_images && !log) throw std::invalid_argument("--log-images records with --log: add --log");
  } catch (const std::exception& e) {
    std::cerr << "bookgrasp_eval_full: " << e.what() << "\n";
    usage(std::cerr);
    return 2;
  }
  if (!merge.empty()) return merge_runs(merge, out, cmd.str());
  if (budget <= 0) budget = books > 0 ? 240.0 * books : 3600.0;
  if (!scene_file.empty()) scene_file = std::filesystem::absolute(scene_file).string();
  std::filesystem::create_directories(out);

  // What makes two scenes of the same seed the same scene: merged and resumed runs must agree on it.
  std::ostringstream opt;
  opt << "scene=" << (scene_file.empty() ? "default" : scene_file) << " books=" << books << " budget_s=" << budget
      << " done_after_s=" << done_after << " stereo_hz=" << stereo_hz << " hand_hz=" << hand_hz
      << " source=" << std::filesystem::absolute(source_dir).lexically_normal().string();
  for (const auto& o : overrides) opt << " set=" << o;
  const std::string options = opt.str();

  std::map<uint64_t, SceneRecord> kept;
  if (resume) {
    try {
      kept = read_scene_records(out);
    } catch (const std::exception& e) {
      std::cerr << "bookgrasp_eval_full: --resume: " << e.what() << "\n";
      return 2;
    }
    for (const auto& [s, r] : kept)
      if (r.options != options) {
        std::cerr << "bookgrasp_eval_full: --resume: " << out << "/scenes/seed_" << s
                  << ".yaml ran with other options:\n  " << r.options << "\nnot\n  " << options
                  << "\nUse another --out, or the same options.\n";
        return 2;
      }
  }
  std::filesystem::create_directories(out + "/scenes");

  EvalMetrics metrics;
  const MetricTolerances tol;
  std::map<uint64_t, std::string> rows;
  const bool tty = isatty(2);
  const auto wall0 = std::chrono::steady_clock::now();
  int ran = 0, to_run = 0;
  for (int k = 0; k < scenes; ++k) to_run += kept.count(static_cast<uint64_t>(seed) + k) ? 0 : 1;
  for (int k = 0; k < scenes; ++k) {
    const uint64_t s = static_cast<uint64_t>(seed) + k;
    if (const auto it = kept.find(s); it != kept.end()) {
      add_metrics(it->second.metrics, &metrics);
      rows[s] = it->second.csv_row;
      std::cerr << "scene " << (k + 1) << "/" << scenes << " seed " << s << ": kept from " << out << "/scenes/\n";
      continue;
    }
    FullCycleOptions o;
    o.source_dir = source_dir;
    o.scene_file = scene_file;
    o.seed = s;
    o.progress_file = out + "/progress/seed_" + std::to_string(s) + ".yaml";
    o.user_done_after_s = done_after;
    o.stereo_rate_hz = stereo_hz;
    o.hand_rate_hz = hand_hz;
    o.verbose = verbose;
    o.overrides = overrides;
    o.snapshot_period_s = snapshot_period;
    if (log) o.log_file = out + "/logs/seed_" + std::to_string(s) + ".lcmlog";
    o.log_channels = log_channels;
    o.log_images = log_images;
    if (snapshots) o.snapshot_dir = out + "/snapshots/seed_" + std::to_string(s);
    std::optional<SceneOutcome> ran_scene;
    try {
      ran_scene = SceneOutcome{s, run_full_cycle(o, budget, books)};
    } catch (const ConfigError& e) {
      std::cerr << "bookgrasp_eval_full: configuration: " << e.what() << "\nNo scene of seed " << s
                << " or later was run or recorded.\n";
      return 2;
    }
    const SceneOutcome& outcome = *ran_scene;
    SceneRecord record;
    record.seed = s;
    record.options = options;
    record.books_per_scene = books;
    accumulate(outcome, books, tol, &record.metrics);
    add_metrics(record.metrics, &metrics);
    const FullCycleResult& r = outcome.result;
    const std::string why = failure_reason(r, books);
    const int moved = books_on_lower_shelf(r);
    std::ostringstream row;
    row << s << "," << r.end << "," << r.books_on_upper_shelf << "," << moved << "," << r.grasp_attempts << ","
        << r.grasp_successes << "," << r.sim_s << "," << r.wall_s << ",\"" << why << "\"";
    record.csv_row = row.str();
    rows[s] = record.csv_row;
    // The scene is kept before anything else is written: a run stopped from here on loses nothing.
    const std::string record_file = out + "/scenes/seed_" + std::to_string(s) + ".yaml";
    std::ofstream(record_file + ".part") << scene_record_yaml(record);
    std::filesystem::rename(record_file + ".part", record_file);
    write_csv(out, rows);
    if (!why.empty() || verbose) {
      std::ofstream tr(out + "/trace_seed_" + std::to_string(s) + ".txt");
      for (const auto& l : r.trace) tr << l << "\n";
    }
    // Partial results are usable while a long run goes on.
    std::ofstream(out + "/metrics.json") << metrics_json(metrics, cmd.str());
    ++ran;
    const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    const double eta = el / ran * (to_run - ran);
    if (tty)
      std::cerr << progress_bar(k + 1, scenes, eta, static_cast<int>(metrics.failures.size())) << std::flush;
    else
      std::cerr << "scene " << (k + 1) << "/" << scenes << " seed " << s << ": " << r.end << ", moved " << moved << ", "
                << r.wall_s << " s wall" << (why.empty() ? "" : " FAILED: " + why) << "\n";
  }
  write_csv(out, rows);
  std::ofstream(out + "/metrics.json") << metrics_json(metrics, cmd.str());
  if (tty) std::cerr << "\n";
  write_report(out, metrics, cmd.str(), books);
  std::cout << metrics_json(metrics, cmd.str());
  std::cout << "report: " << out << "/report.md\n";
  return 0;
}
