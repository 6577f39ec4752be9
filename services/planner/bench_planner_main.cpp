// bookgrasp_bench_planner: the planner benchmark of issue 6 (item 6).
// Same library queries for every planner in one run; writes DIR/metrics.json.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <sstream>

#include "common/version.h"
#include "services/planner/bench_queries.h"

using namespace bookgrasp;

namespace {

void usage() {
  std::cout << "bookgrasp_bench_planner - planner benchmark over library queries\n\n"
               "usage: bookgrasp_bench_planner [--queries N] [--seed S] [--out DIR] [--config FILE]\n"
               "                               [--planners A,B,C] [--time-budget SECONDS] [--verify]\n\n"
               "  --queries N       number of queries (default 120; kinds pregrasp/holder/lower in turn)\n"
               "  --seed S          scene seed (default 1)\n"
               "  --out DIR         output folder for metrics.json (default bench_planner_out)\n"
               "  --config FILE     planner configuration (default config/services/planner.yaml)\n"
               "  --planners LIST   comma-separated (default CellBiRRT,RRTConnect,BiTRRT)\n"
               "  --time-budget S   per-query budget (default 1.0)\n"
               "  --verify          re-check every path densely (0.002 rad, no margin) and count violations\n";
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double idx = p * (v.size() - 1);
  const size_t lo = static_cast<size_t>(std::floor(idx)), hi = static_cast<size_t>(std::ceil(idx));
  return v[lo] + (idx - lo) * (v[hi] - v[lo]);
}

struct Stats {
  int runs = 0, ok = 0, violations = 0;
  std::vector<double> ms, length, ik_ms, search_ms, simplify_ms, steps;
  double total_search_ms = 0.0, total_steps = 0.0;  // search steps per ms of search: calibrates max_search_steps
  std::map<std::string, int> failures;
  std::map<std::string, std::pair<int, int>> by_kind;  // ok, runs
};

}  // namespace

int main(int argc, char** argv) {
  int queries = 120;
  uint64_t seed = 1;
  std::string out_dir = "bench_planner_out";
  std::string config = std::string(kSourceDir) + "/config/services/planner.yaml";
  std::vector<std::string> planners{"CellBiRRT", "RRTConnect", "BiTRRT"};
  double budget = 1.0;
  bool verify = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << a << " needs a value (see --help)\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      usage();
      return 0;
    } else if (a == "--queries") {
      queries = std::atoi(value().c_str());
    } else if (a == "--seed") {
      seed = std::strtoull(value().c_str(), nullptr, 10);
    } else if (a == "--out") {
      out_dir = value();
    } else if (a == "--config") {
      config = value();
    } else if (a == "--planners") {
      planners.clear();
      std::stringstream ss(value());
      for (std::string p; std::getline(ss, p, ',');) planners.push_back(p);
    } else if (a == "--time-budget") {
      budget = std::atof(value().c_str());
    } else if (a == "--verify") {
      verify = true;
    } else {
      std::cerr << "unknown argument '" << a << "' (see --help)\n";
      return 2;
    }
  }
  if (queries <= 0 || !(budget > 0)) {
    std::cerr << "--queries and --time-budget must be positive\n";
    return 2;
  }
  try {
    const PlannerSettings settings = PlannerSettings::load(config);
    PlannerStack stack(settings);
    std::cerr << "generating " << queries << " library queries (seed " << seed << ")...\n";
    const std::vector<BenchQuery> library = make_library_queries(settings, stack, queries, seed);
    if (static_cast<int>(library.size()) < queries)
      std::cerr << "warning: only " << library.size() << " queries could be generated\n";
    std::map<std::string, Stats> stats;
    PlanningScene scene = stack.scene;
    for (size_t qi = 0; qi < library.size(); ++qi) {
      const BenchQuery& q = library[qi];
      apply_query_scene(q, settings.held_book, scene);
      for (const std::string& name : planners) {
        PlanRequest req = q.request;
        req.planner = name;
        req.time_budget_s = budget;
        const PlanOutcome r = stack.planner.plan(scene, req);
        Stats& s = stats[name];
        ++s.runs;
        ++s.by_kind[q.kind].second;
        s.ms.push_back(1000.0 * r.planning_time_s);
        s.ik_ms.push_back(1000.0 * r.goal_ik_time_s);
        s.search_ms.push_back(1000.0 * r.search_time_s);
        s.simplify_ms.push_back(1000.0 * r.simplify_time_s);
        s.steps.push_back(static_cast<double>(r.search_steps));
        s.total_search_ms += 1000.0 * r.search_time_s;
        s.total_steps += static_cast<double>(r.search_steps);
        if (r.success) {
          ++s.ok;
          ++s.by_kind[q.kind].first;
          s.length.push_back(r.path_length_rad);
          if (verify) {
            for (size_t k = 1; k < r.path.size(); ++k) {
              if (!segment_collision_free(scene, r.path[k - 1], r.path[k], 0.002, false)) {
                ++s.violations;
                break;
              }
            }
          }
        } else {
          ++s.failures[to_string(r.failure)];
        }
      }
      std::cerr << "\r[" << std::setw(4) << qi + 1 << "/" << library.size() << "]";
      for (const std::string& name : planners) {
        const Stats& s = stats[name];
        std::cerr << "  " << name << " " << s.ok << "/" << s.runs << " med " << std::fixed << std::setprecision(1)
                  << percentile(s.ms, 0.5) << " ms";
      }
      std::cerr << std::flush;
    }
    std::cerr << "\n";

    std::filesystem::create_directories(out_dir);
    const std::string path = out_dir + "/metrics.json";
    std::ofstream js(path);
    js << std::setprecision(6) << "{\n";
    js << "  \"benchmark\": {\"queries\": " << library.size() << ", \"seed\": " << seed << ", \"time_budget_s\": "
       << budget << ", \"config\": \"" << config << "\", \"version\": \"" << kVersion << "\"},\n";
    for (size_t pi = 0; pi < planners.size(); ++pi) {
      const Stats& s = stats[planners[pi]];
      js << "  \"" << planners[pi] << "\": {\n";
      js << "    \"success_rate\": " << (s.runs ? static_cast<double>(s.ok) / s.runs : 0.0) << ",\n";
      js << "    \"ms\": {\"median\": " << percentile(s.ms, 0.5) << ", \"p95\": " << percentile(s.ms, 0.95)
         << ", \"max\": " << percentile(s.ms, 1.0) << "},\n";
      js << "    \"path_length\": {\"median\": " << percentile(s.length, 0.5) << "},\n";
      js << "    \"parts_ms_median\": {\"goal_ik\": " << percentile(s.ik_ms, 0.5) << ", \"search\": "
         << percentile(s.search_ms, 0.5) << ", \"simplify\": " << percentile(s.simplify_ms, 0.5) << "},\n";
      js << "    \"search_steps\": {\"median\": " << percentile(s.steps, 0.5)
         << ", \"p95\": " << percentile(s.steps, 0.95) << ", \"max\": " << percentile(s.steps, 1.0)
         << ", \"per_search_ms\": " << (s.total_search_ms > 0 ? s.total_steps / s.total_search_ms : 0.0) << "},\n";
      js << "    \"runs\": " << s.runs << ",\n    \"failures\": {";
      bool first = true;
      for (const auto& [k, v] : s.failures) {
        js << (first ? "" : ", ") << "\"" << k << "\": " << v;
        first = false;
      }
      js << "},\n    \"success_by_kind\": {";
      first = true;
      for (const auto& [k, v] : s.by_kind) {
        js << (first ? "" : ", ") << "\"" << k << "\": " << (v.second ? static_cast<double>(v.first) / v.second : 0.0);
        first = false;
      }
      js << "}";
      if (verify) js << ",\n    \"dense_recheck_violations\": " << s.violations;
      js << "\n  }" << (pi + 1 < planners.size() ? "," : "") << "\n";
    }
    js << "}\n";
    std::cout << "wrote " << path << "\n";
    for (const std::string& name : planners) {
      const Stats& s = stats[name];
      std::cout << std::left << std::setw(11) << name << " success " << std::fixed << std::setprecision(1)
                << 100.0 * s.ok / std::max(1, s.runs) << " %  ms median " << percentile(s.ms, 0.5) << " p95 "
                << percentile(s.ms, 0.95) << " max " << percentile(s.ms, 1.0) << "  path median "
                << std::setprecision(2) << percentile(s.length, 0.5) << " rad";
      std::cout << "  [median ms: goal IK " << std::setprecision(1) << percentile(s.ik_ms, 0.5) << ", search "
                << percentile(s.search_ms, 0.5) << ", simplify " << percentile(s.simplify_ms, 0.5) << "]";
      std::cout << "  search steps median " << std::setprecision(0) << percentile(s.steps, 0.5) << " max "
                << percentile(s.steps, 1.0) << " (" << std::setprecision(1)
                << (s.total_search_ms > 0 ? s.total_steps / s.total_search_ms : 0.0) << " per search ms)";
      if (verify) std::cout << "  dense violations " << s.violations;
      std::cout << "\n";
    }
  } catch (const std::exception& e) {
    std::cerr << "bookgrasp_bench_planner: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
