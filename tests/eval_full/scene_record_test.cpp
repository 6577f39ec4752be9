// Scene records (services/eval_full/scene_record.h): what a resumed or merged evaluation is made of must give the
// figures of one run over the same scenes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "services/eval_full/scene_record.h"
#include "tests/eval_full/hand_made_scenes.h"

using namespace bookgrasp;
using namespace bookgrasp::test_scenes;

namespace {

SceneRecord record_of(const SceneOutcome& o, const std::string& options = "books=0") {
  SceneRecord r;
  r.seed = o.seed;
  r.options = options;
  r.books_per_scene = 0;
  r.csv_row = std::to_string(o.seed) + ",DONE,2,2,3,2,220,1.5,\"a \\\"quoted\\\" reason, with a comma\"";
  accumulate(o, 0, MetricTolerances{}, &r.metrics);
  return r;
}

/// A second, different scene: a width 0.1 mm off that 17 digits must keep, a failure of its own.
SceneOutcome other_scene(uint64_t seed) {
  SceneOutcome o = done_scene(seed);
  o.result.books[0].measured_width_m = 0.0201;
  o.result.final_truth.books[1].place = "other";
  o.result.plan_ms = {12.5, 1.0 / 3.0};
  o.result.wall_s = 61.25;
  return o;
}

void write_record(const std::filesystem::path& dir, const SceneRecord& r) {
  std::filesystem::create_directories(dir / "scenes");
  std::ofstream(dir / "scenes" / ("seed_" + std::to_string(r.seed) + ".yaml")) << scene_record_yaml(r);
}

std::filesystem::path fresh_dir(const std::string& name) {
  const auto d = std::filesystem::temp_directory_path() / ("scene_record_test_" + name);
  std::filesystem::remove_all(d);
  return d;
}

}  // namespace

TEST(SceneRecord, ReadsBackWhatItWrote) {
  const SceneRecord r = record_of(other_scene(12));
  const SceneRecord back = parse_scene_record(scene_record_yaml(r), "test");
  EXPECT_EQ(back.seed, 12u);
  EXPECT_EQ(back.options, r.options);
  EXPECT_EQ(back.books_per_scene, 0);
  EXPECT_EQ(back.csv_row, r.csv_row);
  // Every figure, bit for bit.
  EXPECT_EQ(metrics_json(back.metrics, "c"), metrics_json(r.metrics, "c"));
  EXPECT_EQ(back.metrics.width_error_mm, r.metrics.width_error_mm);
  EXPECT_EQ(back.metrics.plan_ms, r.metrics.plan_ms);
  EXPECT_EQ(back.metrics.failure_modes, r.metrics.failure_modes);
  ASSERT_EQ(back.metrics.failures.size(), 1u);
  EXPECT_EQ(back.metrics.failures[0], r.metrics.failures[0]);
}

TEST(SceneRecord, AddedRecordsGiveTheFiguresOfOneRun) {
  EvalMetrics one_run;
  for (uint64_t s : {3u, 4u, 5u}) accumulate(s == 4 ? other_scene(s) : done_scene(s), 0, MetricTolerances{}, &one_run);
  EvalMetrics added;
  for (uint64_t s : {3u, 4u, 5u})
    add_metrics(parse_scene_record(scene_record_yaml(record_of(s == 4 ? other_scene(s) : done_scene(s))), "t").metrics,
                &added);
  EXPECT_EQ(added.scenes, 3);
  EXPECT_EQ(metrics_json(added, "c"), metrics_json(one_run, "c"));
}

TEST(SceneRecord, MergesRunsOverDifferentSeeds) {
  const auto a = fresh_dir("a"), b = fresh_dir("b");
  write_record(a, record_of(done_scene(1)));
  write_record(a, record_of(other_scene(2)));
  write_record(b, record_of(done_scene(3)));
  const auto all = merged_scene_records({a.string(), b.string()});
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(all.begin()->first, 1u);
  EXPECT_EQ(all.rbegin()->first, 3u);
  EXPECT_EQ(all.at(2).metrics.failures.size(), 1u);
}

TEST(SceneRecord, RefusesRunsThatCannotBeMerged) {
  const auto a = fresh_dir("c"), b = fresh_dir("d"), c = fresh_dir("e"), empty = fresh_dir("f");
  write_record(a, record_of(done_scene(1)));
  write_record(b, record_of(done_scene(1)));              // the same seed twice
  write_record(c, record_of(done_scene(2), "books=1"));   // other options
  std::filesystem::create_directories(empty / "scenes");  // no scene at all
  const auto message = [](const std::vector<std::string>& dirs) {
    try {
      merged_scene_records(dirs);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message({a.string(), b.string()}).find("seed 1 is in both"), std::string::npos);
  EXPECT_NE(message({a.string(), c.string()}).find("other options"), std::string::npos);
  EXPECT_NE(message({a.string(), empty.string()}).find("holds no scenes"), std::string::npos);
}

/// A scene record's text without the lines of the keys starting with `prefix`: a record from before they existed.
std::string without_keys(const std::string& text, const std::string& prefix) {
  std::string out;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind(prefix, 0) != 0) out += line + "\n";
  return out;
}

TEST(SceneRecord, PlateClosesRoundTripAndARecordFromBeforeThemReadsAsNone) {
  SceneOutcome o = other_scene(14);
  o.result.closes = {{0.0256, 0.0250, "held_alone"}, {0.0310, 0.0250, "double_lift"}};
  const SceneRecord r = record_of(o);
  const SceneRecord back = parse_scene_record(scene_record_yaml(r), "test");
  EXPECT_EQ(back.metrics.plates_over_fore_edge_mm[0], r.metrics.plates_over_fore_edge_mm[0]);
  EXPECT_EQ(back.metrics.plates_over_fore_edge_mm[1], r.metrics.plates_over_fore_edge_mm[1]);
  // A stop 27 record (no plates_over_fore_edge_mm_* keys): read, with no closes.
  const std::string old_text = without_keys(scene_record_yaml(r), "plates_over_fore_edge_mm_");
  ASSERT_NE(old_text, scene_record_yaml(r));
  const SceneRecord before = parse_scene_record(old_text, "stop27/scenes/seed_14.yaml");
  for (const auto& v : before.metrics.plates_over_fore_edge_mm) EXPECT_TRUE(v.empty());
  EXPECT_EQ(before.metrics.width_error_mm, r.metrics.width_error_mm);
}

TEST(SceneRecord, UprightCountsRoundTripAndARecordFromBeforeThemReadsAsNoneChecked) {
  const SceneRecord r = record_of(done_scene(15));
  ASSERT_EQ(r.metrics.books_upright_checked, 2);
  ASSERT_EQ(r.metrics.books_upright_on_lower_shelf, 2);
  const SceneRecord back = parse_scene_record(scene_record_yaml(r), "test");
  EXPECT_EQ(back.metrics.books_upright_checked, 2);
  EXPECT_EQ(back.metrics.books_upright_on_lower_shelf, 2);
  // A stop 30 record (no books_upright_* keys): read, nothing checked.
  const std::string old_text = without_keys(scene_record_yaml(r), "books_upright_");
  ASSERT_NE(old_text, scene_record_yaml(r));
  const SceneRecord before = parse_scene_record(old_text, "stop30/scenes/seed_15.yaml");
  EXPECT_EQ(before.metrics.books_upright_checked, 0);
  EXPECT_EQ(before.metrics.books_moved, r.metrics.books_moved);
}

TEST(SceneRecord, StripeEndsAndDisagreementsRoundTripAndARecordFromBeforeThemReadsAsNone) {
  SceneOutcome o = other_scene(16);
  const Eigen::Vector3d end(0.30, 0.12, 0.40);
  o.result.stripes = {{0, end + Eigen::Vector3d(1.0 / 3.0e3, -0.003, -0.46), end}};
  const SceneRecord r = record_of(o);
  const SceneRecord back = parse_scene_record(scene_record_yaml(r), "test");
  EXPECT_EQ(back.metrics.stripes, 1);
  EXPECT_EQ(back.metrics.stripes_within, 1);
  EXPECT_EQ(back.metrics.stripe_error_mm[0], r.metrics.stripe_error_mm[0]);  // bit for bit
  EXPECT_EQ(back.metrics.stripe_error_mm[1], r.metrics.stripe_error_mm[1]);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(back.metrics.p1_p2_disagreements[k], r.metrics.p1_p2_disagreements[k]);
  // A stop 40 record (no stripe* or p1_p2_disagree_* keys): read, none measured.
  const std::string old_text = without_keys(without_keys(scene_record_yaml(r), "stripe"), "p1_p2_disagree_");
  ASSERT_NE(old_text, scene_record_yaml(r));
  const SceneRecord before = parse_scene_record(old_text, "stop40/scenes/seed_16.yaml");
  EXPECT_EQ(before.metrics.stripes, 0);
  EXPECT_TRUE(before.metrics.stripe_error_mm[0].empty());
  for (int k = 0; k < 4; ++k) EXPECT_EQ(before.metrics.p1_p2_disagreements[k], 0);
  EXPECT_EQ(before.metrics.width_error_mm, r.metrics.width_error_mm);
}

TEST(SceneRecord, BooksPassedOverRoundTripAndARecordFromBeforeThemReadsAsNone) {
  SceneOutcome o = other_scene(17);
  o.result.books[0].passed_over_not_standing = {3, 4};
  const SceneRecord r = record_of(o);
  EXPECT_EQ(r.metrics.books_passed_over_not_standing, 2);
  EXPECT_EQ(parse_scene_record(scene_record_yaml(r), "test").metrics.books_passed_over_not_standing, 2);
  // A record of 5e55419 (no such key, docs/eval_runs): read, none passed over.
  const std::string old_text = without_keys(scene_record_yaml(r), "books_passed_over");
  ASSERT_NE(old_text, scene_record_yaml(r));
  const SceneRecord before = parse_scene_record(old_text, "full-5e55419/out_5000/scenes/seed_17.yaml");
  EXPECT_EQ(before.metrics.books_passed_over_not_standing, 0);
  EXPECT_EQ(before.metrics.grasp_attempts, r.metrics.grasp_attempts);
}

TEST(SceneRecord, AScenesShortfallsAreReadFromItsCountsSoOlderRecordsListThemToo) {
  // The record stores no seeds per shortfall: they come from its counts (the grasp retry, the 15 mm width and the
  // P2 20 mm off of done_scene).
  std::string text = scene_record_yaml(record_of(done_scene(21)));
  ASSERT_EQ(text.find("shortfall"), std::string::npos) << text;
  const SceneRecord back = parse_scene_record(text, "t");
  EXPECT_EQ(back.metrics.shortfall_seeds, record_of(done_scene(21)).metrics.shortfall_seeds);
  const std::vector<uint64_t> seed = {21};
  EXPECT_EQ(back.metrics.shortfall_seeds.at("grasp_not_held_alone"), seed);
  EXPECT_EQ(back.metrics.shortfall_seeds.at("width_off_by_more_than_1cm"), seed);
  EXPECT_EQ(back.metrics.shortfall_seeds.at("p1_p2_p2_off_p1_near_corner"), seed);
  EXPECT_EQ(back.metrics.shortfall_seeds.size(), 3u);
  // Merged in any order, each kind's seeds come out sorted.
  EvalMetrics merged;
  for (uint64_t s : {30u, 22u, 25u})
    add_metrics(parse_scene_record(scene_record_yaml(record_of(done_scene(s))), "t").metrics, &merged);
  EXPECT_EQ(merged.shortfall_seeds.at("grasp_not_held_alone"), (std::vector<uint64_t>{22, 25, 30}));
}

TEST(SceneRecord, ABadFileIsNamedWithItsKey) {
  std::string text = scene_record_yaml(record_of(done_scene(1)));
  const auto at = text.find("grasp_attempts:");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, std::string("grasp_attempts").size(), "grasp_tries");
  try {
    parse_scene_record(text, "dir/scenes/seed_1.yaml");
    FAIL() << "a record without grasp_attempts was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("dir/scenes/seed_1.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'grasp_attempts' is missing"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_scene_record("[1, 2]", "x"), std::runtime_error);
  EXPECT_THROW(parse_scene_record("seed: [", "x"), std::runtime_error);
}
