#include "services/eval_full/scene_record.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace bookgrasp {

namespace {

/// The integer counts of EvalMetrics by their YAML key.
template <typename M>
auto counts(M& m) {
  return std::vector<std::pair<const char*, decltype(&m.scenes)>>{
      {"scenes", &m.scenes},
      {"books_targeted", &m.books_targeted},
      {"books_moved", &m.books_moved},
      {"books_handed_over", &m.books_handed_over},
      {"books_handed_over_unplaceable", &m.books_handed_over_unplaceable},
      {"books_passed_over_not_standing", &m.books_passed_over_not_standing},
      {"grasp_attempts", &m.grasp_attempts},
      {"grasp_successes", &m.grasp_successes},
      {"books_carried_along", &m.books_carried_along},
      {"untargeted_books_off_the_upper_shelf", &m.untargeted_books_off_the_upper_shelf},
      {"holder_releases", &m.holder_releases},
      {"holder_placed", &m.holder_placed},
      {"holder_retreats", &m.holder_retreats},
      {"holder_standing", &m.holder_standing},
      {"books_upright_checked", &m.books_upright_checked},
      {"books_upright_on_lower_shelf", &m.books_upright_on_lower_shelf},
      {"decisions", &m.decisions},
      {"decisions_agreeing", &m.decisions_agreeing},
      {"widths", &m.widths},
      {"widths_within", &m.widths_within},
      {"p1_p2_disagree_p1_off_in_y", &m.p1_p2_disagreements[0]},
      {"p1_p2_disagree_p1_above_corner", &m.p1_p2_disagreements[1]},
      {"p1_p2_disagree_p1_below_corner", &m.p1_p2_disagreements[2]},
      {"p1_p2_disagree_p2_off_p1_near_corner", &m.p1_p2_disagreements[3]},
      {"stripes", &m.stripes},
      {"stripes_within", &m.stripes_within},
  };
}

/// The samples of EvalMetrics by their YAML key.
template <typename M>
auto samples(M& m) {
  return std::vector<std::pair<const char*, decltype(&m.cycle_s)>>{
      {"width_error_mm", &m.width_error_mm},
      {"p1_error_mm_x", &m.p1_error_mm[0]},
      {"p1_error_mm_y", &m.p1_error_mm[1]},
      {"p1_error_mm_z", &m.p1_error_mm[2]},
      {"gp_error_mm_x", &m.gp_error_mm[0]},
      {"gp_error_mm_y", &m.gp_error_mm[1]},
      {"gp_error_mm_z", &m.gp_error_mm[2]},
      {"gp_base_error_mm_x", &m.gp_base_error_mm[0]},
      {"gp_base_error_mm_y", &m.gp_base_error_mm[1]},
      {"gp_base_error_mm_z", &m.gp_base_error_mm[2]},
      {"p1_p2_dy_mm", &m.p1_p2_dy_mm},
      {"p1_p2_dx_mm", &m.p1_p2_dx_mm},
      {"stripe_error_mm_x", &m.stripe_error_mm[0]},
      {"stripe_error_mm_y", &m.stripe_error_mm[1]},
      {"cycle_s", &m.cycle_s},
      {"plan_ms", &m.plan_ms},
      {"scene_wall_s", &m.scene_wall_s},
      {"plates_over_fore_edge_mm_held_alone", &m.plates_over_fore_edge_mm[0]},
      {"plates_over_fore_edge_mm_double_lift", &m.plates_over_fore_edge_mm[1]},
      {"plates_over_fore_edge_mm_not_held", &m.plates_over_fore_edge_mm[2]},
      {"plates_over_fore_edge_mm_backed_out", &m.plates_over_fore_edge_mm[3]},
  };
}

/// Keys added after the first scene records (stop 28: the plate samples; stop 31: the upright counts; stop 41: the
/// stripe end and the P1-P2 disagreements by mode; stop 42: the books passed over): a record without them measured
/// none (empty, 0).
bool added_later(const std::string& key) {
  return key.rfind("plates_over_fore_edge_mm_", 0) == 0 || key.rfind("books_upright_", 0) == 0 ||
         key.rfind("stripe", 0) == 0 || key.rfind("p1_p2_disagree_", 0) == 0 ||
         key == std::string("books_passed_over_not_standing");
}

std::string exact(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

YAML::Node required(const YAML::Node& n, const std::string& key, const std::string& where) {
  const YAML::Node v = n[key];
  if (!v) throw std::runtime_error(where + ": key '" + key + "' is missing (not a scene record of this version?)");
  return v;
}

}  // namespace

std::string scene_record_yaml(const SceneRecord& r) {
  YAML::Emitter e;
  e << YAML::BeginMap;
  e << YAML::Key << "seed" << YAML::Value << r.seed;
  e << YAML::Key << "options" << YAML::Value << YAML::DoubleQuoted << r.options;
  e << YAML::Key << "books_per_scene" << YAML::Value << r.books_per_scene;
  e << YAML::Key << "csv_row" << YAML::Value << YAML::DoubleQuoted << r.csv_row;
  for (const auto& [key, v] : counts(r.metrics)) e << YAML::Key << key << YAML::Value << *v;
  for (const auto& [key, v] : samples(r.metrics)) {
    e << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (double x : *v) e << YAML::Value << exact(x);
    e << YAML::EndSeq;
  }
  e << YAML::Key << "failures" << YAML::Value << YAML::BeginSeq;
  for (const auto& [seed, why] : r.metrics.failures)
    e << YAML::Flow << YAML::BeginMap << YAML::Key << "seed" << YAML::Value << seed << YAML::Key << "reason"
      << YAML::Value << YAML::DoubleQuoted << why << YAML::EndMap;
  e << YAML::EndSeq;
  e << YAML::Key << "failure_modes" << YAML::Value << YAML::BeginMap;
  for (const auto& [why, n] : r.metrics.failure_modes) e << YAML::Key << YAML::DoubleQuoted << why << YAML::Value << n;
  e << YAML::EndMap;
  e << YAML::EndMap;
  return std::string(e.c_str()) + "\n";
}

SceneRecord parse_scene_record(const std::string& text, const std::string& where) {
  SceneRecord r;
  try {
    const YAML::Node n = YAML::Load(text);
    if (!n.IsMap()) throw std::runtime_error(where + ": not a YAML map");
    r.seed = required(n, "seed", where).as<uint64_t>();
    r.options = required(n, "options", where).as<std::string>();
    r.books_per_scene = required(n, "books_per_scene", where).as<int>();
    r.csv_row = required(n, "csv_row", where).as<std::string>();
    for (const auto& [key, v] : counts(r.metrics))
      if (!added_later(key) || n[key]) *v = required(n, key, where).as<int>();
    for (const auto& [key, v] : samples(r.metrics))
      if (!added_later(key) || n[key]) *v = required(n, key, where).as<std::vector<double>>();
    for (const auto& f : required(n, "failures", where))
      r.metrics.failures.emplace_back(required(f, "seed", where).as<uint64_t>(),
                                      required(f, "reason", where).as<std::string>());
    for (const auto& kv : required(n, "failure_modes", where))
      r.metrics.failure_modes[kv.first.as<std::string>()] = kv.second.as<int>();
    for (const auto& [kind, n] : shortfall_counts(r.metrics)) r.metrics.shortfall_seeds[kind] = {r.seed};
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(where + ": " + e.what());
  }
  return r;
}

std::map<uint64_t, SceneRecord> read_scene_records(const std::string& dir) {
  std::map<uint64_t, SceneRecord> out;
  const std::filesystem::path scenes = std::filesystem::path(dir) / "scenes";
  if (!std::filesystem::is_directory(scenes)) return out;
  for (const auto& f : std::filesystem::directory_iterator(scenes)) {
    const std::string name = f.path().filename().string();
    if (name.rfind("seed_", 0) != 0 || f.path().extension() != ".yaml") continue;
    std::ifstream in(f.path());
    std::stringstream text;
    text << in.rdbuf();
    SceneRecord r = parse_scene_record(text.str(), f.path().string());
    const uint64_t seed = r.seed;
    out.emplace(seed, std::move(r));
  }
  return out;
}

std::map<uint64_t, SceneRecord> merged_scene_records(const std::vector<std::string>& dirs) {
  std::map<uint64_t, SceneRecord> all;
  std::map<uint64_t, std::string> where;
  for (const auto& d : dirs) {
    auto records = read_scene_records(d);
    if (records.empty()) throw std::runtime_error(d + " holds no scenes/seed_*.yaml");
    for (auto& [seed, r] : records) {
      if (!all.empty() && r.options != all.begin()->second.options)
        throw std::runtime_error("seed " + std::to_string(seed) + " in " + d + " ran with other options:\n  " +
                                 r.options + "\nnot\n  " + all.begin()->second.options);
      if (all.count(seed))
        throw std::runtime_error("seed " + std::to_string(seed) + " is in both " + where[seed] + " and " + d);
      where[seed] = d;
      all.emplace(seed, std::move(r));
    }
  }
  return all;
}

void add_metrics(const EvalMetrics& from, EvalMetrics* into) {
  const auto src = counts(from);
  const auto dst = counts(*into);
  for (size_t i = 0; i < dst.size(); ++i) *dst[i].second += *src[i].second;
  const auto ssrc = samples(from);
  const auto sdst = samples(*into);
  for (size_t i = 0; i < sdst.size(); ++i)
    sdst[i].second->insert(sdst[i].second->end(), ssrc[i].second->begin(), ssrc[i].second->end());
  into->failures.insert(into->failures.end(), from.failures.begin(), from.failures.end());
  std::stable_sort(into->failures.begin(), into->failures.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [why, n] : from.failure_modes) into->failure_modes[why] += n;
  for (const auto& [kind, seeds] : from.shortfall_seeds) {
    std::vector<uint64_t>& all = into->shortfall_seeds[kind];
    all.insert(all.end(), seeds.begin(), seeds.end());
    std::sort(all.begin(), all.end());
    all.erase(std::unique(all.begin(), all.end()), all.end());
  }
}

}  // namespace bookgrasp
