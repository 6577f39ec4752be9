#pragma once
/// @file
/// One evaluated scene on disk (DIR/scenes/seed_<S>.yaml): the scene's share of the evaluation's figures, written
/// as soon as the scene ends. A long evaluation can so be resumed after its process was stopped, and runs split
/// over several processes (seed ranges) can be merged into one report that equals a single run's.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "services/eval_full/full_cycle_metrics.h"

namespace bookgrasp {

/// A scene as the evaluation keeps it on disk.
struct SceneRecord {
  uint64_t seed = 0;
  /// The options the scene ran with (scene file, books, budget, rates, overrides, source tree): scenes run with
  /// different options are not merged.
  std::string options;
  int books_per_scene = 1;  ///< the harness's max_books (0 = all books)
  std::string csv_row;      ///< its scenes.csv line (no newline)
  EvalMetrics metrics;      ///< this scene alone, accumulated with `accumulate` (scenes == 1)
};

/// The YAML text of `r`. Numbers are written with 17 significant digits, so reading them back gives the same values.
std::string scene_record_yaml(const SceneRecord& r);

/// Parses `text` (as written by scene_record_yaml). Throws std::runtime_error naming `where` and the missing or bad
/// key.
SceneRecord parse_scene_record(const std::string& text, const std::string& where);

/// Every DIR/scenes/seed_*.yaml in `dir`, by seed; empty when there is no such directory. Throws when a file cannot
/// be parsed (naming it).
std::map<uint64_t, SceneRecord> read_scene_records(const std::string& dir);

/// The scenes of several runs' directories in one map by seed. Throws std::runtime_error naming the directories when
/// a directory holds no scene, a seed is in two of them, or scenes ran with different options.
std::map<uint64_t, SceneRecord> merged_scene_records(const std::vector<std::string>& dirs);

/// Adds `from`'s counts and samples to `into`: the same figures as accumulating both sets of scenes into one, when
/// `from`'s scenes come after `into`'s. Failures and the seeds of each shortfall stay sorted by seed.
void add_metrics(const EvalMetrics& from, EvalMetrics* into);

}  // namespace bookgrasp
