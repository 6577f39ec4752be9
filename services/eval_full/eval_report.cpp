#include "services/eval_full/eval_report.h"

namespace bookgrasp {
void write_report(const std::string&, const EvalMetrics&, const std::string&, int) {}
}  // namespace bookgrasp
