#pragma once
/// @file
/// report.md and its PNG plots (drawn with OpenCV) for the full-cycle evaluation.

#include <string>

#include "services/eval_full/full_cycle_metrics.h"

namespace bookgrasp {

/// Writes `dir`/report.md and `dir`/*.png from `m`; `command` is the command line that made it,
/// `books_per_scene` the harness's max_books (0 = all).
void write_report(const std::string& dir, const EvalMetrics& m, const std::string& command, int books_per_scene);

}  // namespace bookgrasp
