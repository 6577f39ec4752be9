#include "services/eval_full/full_cycle_metrics.h"

#include "services/task_watch/truth_count.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace bookgrasp {

Stats stats_of(std::vector<double> v) {
  Stats s;
  s.n = static_cast<int>(v.size());
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  double sum = 0;
  for (double x : v) sum += x;
  s.mean = sum / v.size();
  s.min = v.front();
  s.max = v.back();
  const size_t n = v.size();
  s.median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  s.p95 = v[std::min(n - 1, static_cast<size_t>(std::ceil(0.95 * n)) - 1)];
  return s;
}

namespace {

/// The first word of the coordinator message, e.g. "plan" or "servo"; keeps failure classes short.
std::string first_words(const std::string& msg, int words) {
  std::istringstream ss(msg);
  std::string w, out;
  for (int i = 0; i < words && ss >> w; ++i) out += (i ? " " : "") + w;
  while (!out.empty() && (out.back() == ':' || out.back() == ',' || out.back() == '.')) out.pop_back();
  return out;
}

}  // namespace

std::string final_place(const FullCycleResult& r, const BookRecord& b) {
  const book_truth_t* t = truth_book(r.final_truth, b.truth_id);
  return t ? t->place : "unknown";
}

double final_tilt_deg(const FullCycleResult& r, const BookRecord& b) {
  const book_truth_t* t = truth_book(r.final_truth, b.truth_id);
  return t ? height_axis_tilt_deg(t->pose) : NAN;
}

std::vector<int> untargeted_books_off_the_upper_shelf(const FullCycleResult& r) {
  std::vector<int> ids;
  for (const auto& t : r.final_truth.books) {
    const bool targeted =
        std::any_of(r.books.begin(), r.books.end(), [&](const BookRecord& b) { return b.truth_id == t.id; });
    if (!targeted && t.place != "upper_shelf") ids.push_back(t.id);
  }
  return ids;
}

int books_on_lower_shelf(const FullCycleResult& r) {
  int n = 0;
  for (const auto& b : r.books) n += b.moved && final_place(r, b) == "lower_shelf" ? 1 : 0;
  return n;
}

std::string failure_reason(const FullCycleResult& r, int max_books) {
  if (r.end == "ERROR") return "ERROR: " + r.message;
  for (const auto& b : r.books)
    if (!b.carried_along.empty())
      return "DOUBLE_LIFT: a grasp took " + std::to_string(b.carried_along.size()) +
             " other book(s) out of the shelf with the target";
  for (const auto& b : r.books)
    if (!b.place_after_holder_release.empty() && b.place_after_holder_release != "holder")
      return "BOOK_NOT_ON_HOLDER after RELEASE_ON_HOLDER: the book is " + b.place_after_holder_release +
             (b.grasp_successes == 0 ? " (it was not in the plates after EXTRACT)" : "");
  for (const auto& b : r.books)
    if (b.standing_on_holder == 0) return "BOOK_NOT_STANDING_ON_HOLDER after RETREAT_FROM_HOLDER";
  for (const auto& b : r.books) {
    const std::string place = final_place(r, b);
    if (b.moved && !b.handed_over && place != "lower_shelf")
      return "BOOK_NOT_ON_LOWER_SHELF at the end: the book is " + place;
  }
  for (const auto& b : r.books) {
    const double tilt = final_tilt_deg(r, b);
    if (b.moved && final_place(r, b) == "lower_shelf" && !(tilt <= kUprightMaxTiltDeg))
      return "BOOK_NOT_UPRIGHT_ON_LOWER_SHELF at the end: it lies tilted by more than " +
             std::to_string(static_cast<int>(kUprightMaxTiltDeg)) + " deg (knocked over)";
  }
  if (const auto off = untargeted_books_off_the_upper_shelf(r); !off.empty())
    return "OTHER_BOOK_OFF_THE_UPPER_SHELF at the end: " + std::to_string(off.size()) +
           " book(s) the task never took left the upper shelf";
  if (r.end == "ABORTED") {
    // "aborted in STATE: book 0: 3 attempts failed (...), last: <cause>": class = state + cause.
    const auto in = r.message.find("aborted in ");
    const std::string state = in == std::string::npos ? "?" : first_words(r.message.substr(in + 11), 1);
    const auto last = r.message.find("last: ");
    std::string cause = last == std::string::npos ? r.message : r.message.substr(last + 6);
    cause = cause.substr(0, cause.find(" within"));  // drop run-specific numbers
    cause = cause.substr(0, cause.find(" after "));
    return "ABORTED in " + state + ": " + first_words(cause, 16);
  }
  if (r.end == "BUDGET") {
    const std::string state = r.trace.empty() ? std::string("?") : r.trace.back();
    std::string last_state = "?";
    for (auto it = r.trace.rbegin(); it != r.trace.rend(); ++it) {
      const auto p = it->find("-> ");
      if (it->find("TASK_STATUS") != std::string::npos && p != std::string::npos) {
        last_state = it->substr(p + 3, it->find(' ', p + 3) - p - 3);
        break;
      }
    }
    return "BUDGET: stuck in " + last_state;
  }
  if (max_books > 0 && r.books_moved < max_books && r.end != "DONE") return "INCOMPLETE: " + r.end;
  if (r.end == "DONE") {
    // Every upper-shelf book should have gone to the lower shelf.
    int left_upper = 0, elsewhere = 0;
    for (const auto& b : r.final_truth.books) {
      const bool handed = std::any_of(r.books.begin(), r.books.end(),
                                      [&](const BookRecord& k) { return k.handed_over && k.truth_id == b.id; });
      if (b.place == "upper_shelf") ++left_upper;
      if (b.place != "upper_shelf" && b.place != "lower_shelf" && !handed) ++elsewhere;
    }
    if (elsewhere > 0) return "DONE with " + std::to_string(elsewhere) + " book(s) neither on a shelf";
    if (left_upper > 0) return "DONE with " + std::to_string(left_upper) + " book(s) left on the upper shelf";
  }
  if (r.grasp_attempts > r.grasp_successes) return "GRASP_RETRIED: a grasp did not hold the book";
  for (const auto& b : r.books)
    if (!b.passed_over_not_standing.empty())
      return "RIGHTMOST_NOT_STANDING: the right-most book leaned more than " +
             std::to_string(static_cast<int>(kStandingMaxTiltDeg)) +
             " deg (fallen, or leaning on the side panel); the right-most standing book was the target";
  for (const auto& b : r.books)
    if (b.handed_over && b.handed_over_unplaceable)
      return "HANDED_OVER: the lower shelf could not take a book; it went back to the holder for the librarian";
  for (const auto& b : r.books)
    if (b.handed_over)
      return "HANDED_OVER: a book too tall for the lower shelf was left on the holder for the librarian";
  return "";
}

int disagreement_mode(const GraspDecisionRecord& d, const MetricTolerances& tol) {
  if (!d.p1_present || !d.truth_known) return -1;
  const Eigen::Vector3d p2_p1 = d.p2_grasp - d.p1_grasp, p1_err = d.p1_grasp - d.p1_true_grasp;
  if (std::abs(p2_p1.y()) <= tol.agreement_y_m && std::abs(p2_p1.x()) <= tol.agreement_x_m) return -1;
  if (std::abs(p1_err.y()) > tol.agreement_y_m) return 0;
  if (p1_err.x() > tol.agreement_x_m) return 1;
  if (p1_err.x() < -tol.agreement_x_m) return 2;
  return 3;
}

std::map<std::string, int> shortfall_counts(const EvalMetrics& m) {
  int classified = 0;
  for (int n : m.p1_p2_disagreements) classified += n;
  std::map<std::string, int> all = {
      {"grasp_not_held_alone", m.grasp_attempts - m.grasp_successes},
      {"untargeted_book_off_the_upper_shelf", m.untargeted_books_off_the_upper_shelf},
      {"p1_p2_unclassified", m.decisions - m.decisions_agreeing - classified},
      {"width_off_by_more_than_1cm", m.widths - m.widths_within},
      {"stripe_end_outside_tolerance", m.stripes - m.stripes_within},
  };
  for (int k = 0; k < 4; ++k) all[std::string("p1_p2_") + kDisagreementModes[k]] = m.p1_p2_disagreements[k];
  std::map<std::string, int> out;
  for (const auto& [kind, n] : all)
    if (n > 0) out[kind] = n;
  return out;
}

void accumulate(const SceneOutcome& o, int max_books, const MetricTolerances& tol, EvalMetrics* m) {
  const FullCycleResult& r = o.result;
  const std::map<std::string, int> short_before = shortfall_counts(*m);
  ++m->scenes;
  m->scene_wall_s.push_back(r.wall_s);
  const int targeted = max_books > 0 ? std::min(max_books, r.books_on_upper_shelf) : r.books_on_upper_shelf;
  m->books_targeted += targeted;
  // A book counts as moved when the coordinator says so and the simulation's truth has it on the lower shelf.
  const int moved = books_on_lower_shelf(r);
  m->books_moved += std::min(moved, targeted > 0 ? targeted : moved);
  for (const auto& b : r.books) {
    m->books_handed_over += b.handed_over ? 1 : 0;
    m->books_handed_over_unplaceable += b.handed_over && b.handed_over_unplaceable ? 1 : 0;
    m->books_passed_over_not_standing += static_cast<int>(b.passed_over_not_standing.size());
  }
  for (const auto& b : r.books) {
    if (!b.moved || final_place(r, b) != "lower_shelf") continue;
    ++m->books_upright_checked;
    m->books_upright_on_lower_shelf += final_tilt_deg(r, b) <= kUprightMaxTiltDeg ? 1 : 0;
  }
  for (const auto& b : r.books) m->books_carried_along += static_cast<int>(b.carried_along.size());
  m->untargeted_books_off_the_upper_shelf += static_cast<int>(untargeted_books_off_the_upper_shelf(r).size());
  m->grasp_attempts += r.grasp_attempts;
  m->grasp_successes += r.grasp_successes;
  m->holder_releases += r.holder_releases;
  m->holder_placed += r.holder_placed;
  // Per book (its last retreat from the holder), as the denominator: a book that goes back onto the holder for the
  // librarian retreats twice, and r.holder_standing counts both.
  for (const auto& b : r.books) {
    m->holder_retreats += b.standing_on_holder >= 0 ? 1 : 0;
    m->holder_standing += b.standing_on_holder == 1 ? 1 : 0;
  }
  for (const auto& d : r.decisions) {
    if (d.truth_known)
      for (int k = 0; k < 3; ++k) {
        m->gp_error_mm[k].push_back((d.gp_grasp[k] - d.p1_true_grasp[k]) * 1e3);
        m->gp_base_error_mm[k].push_back((d.gp_base_true_grasp[k] - d.p1_true_grasp[k]) * 1e3);
      }
    if (!d.p1_present) continue;
    ++m->decisions;
    const double dy = d.p2_grasp.y() - d.p1_grasp.y(), dx = d.p2_grasp.x() - d.p1_grasp.x();
    m->p1_p2_dy_mm.push_back(dy * 1e3);
    m->p1_p2_dx_mm.push_back(dx * 1e3);
    if (std::abs(dy) <= tol.agreement_y_m && std::abs(dx) <= tol.agreement_x_m) ++m->decisions_agreeing;
    if (const int mode = disagreement_mode(d, tol); mode >= 0) ++m->p1_p2_disagreements[mode];
    if (d.truth_known)
      for (int k = 0; k < 3; ++k) m->p1_error_mm[k].push_back(std::abs(d.p1_grasp[k] - d.p1_true_grasp[k]) * 1e3);
  }
  for (const StripeRecord& st : r.stripes) {
    const Eigen::Vector3d e = st.ps_true_grasp - st.end_true_grasp;
    ++m->stripes;
    m->stripes_within += std::abs(e.x()) <= tol.stripe_x_m && std::abs(e.y()) <= tol.stripe_y_m ? 1 : 0;
    m->stripe_error_mm[0].push_back(e.x() * 1e3);
    m->stripe_error_mm[1].push_back(e.y() * 1e3);
  }
  for (const auto& b : r.books) {
    if (b.measured_width_m >= 0 && b.truth_id >= 0 && b.grasp_successes > 0) {  // plates on a held book only
      ++m->widths;
      const double e = std::abs(b.measured_width_m - b.true_width_m);
      m->width_error_mm.push_back(e * 1e3);
      if (e <= tol.width_m) ++m->widths_within;
    }
    if (b.moved && b.end_s >= 0) m->cycle_s.push_back(b.end_s - b.start_s);
  }
  for (double p : r.plan_ms) m->plan_ms.push_back(p);
  for (const PlateClose& c : r.closes)
    for (int k = 0; k < 4; ++k)
      if (c.outcome == kCloseOutcomes[k]) m->plates_over_fore_edge_mm[k].push_back((c.plates_m - c.fore_edge_m) * 1e3);
  const std::string why = failure_reason(r, max_books);
  if (!why.empty()) {
    m->failures.emplace_back(o.seed, why);
    ++m->failure_modes[why];
  }
  for (const auto& [kind, n] : shortfall_counts(*m)) {
    const auto before = short_before.find(kind);
    if (n <= (before == short_before.end() ? 0 : before->second)) continue;
    std::vector<uint64_t>& seeds = m->shortfall_seeds[kind];
    const auto at = std::lower_bound(seeds.begin(), seeds.end(), o.seed);
    if (at == seeds.end() || *at != o.seed) seeds.insert(at, o.seed);
  }
}

namespace {

std::string num(double v) {
  if (!std::isfinite(v)) return "null";
  char b[64];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

std::string rate(int k, int n) {
  return n > 0 ? num(static_cast<double>(k) / n) : "null";
}

std::string esc(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (c == '\n') {
      o += "\\n";
      continue;
    }
    if (static_cast<unsigned char>(c) < 0x20) continue;
    o += c;
  }
  return o;
}

std::string stats_json(const Stats& s) {
  return "{\"n\": " + std::to_string(s.n) + ", \"mean\": " + num(s.mean) + ", \"median\": " + num(s.median) +
         ", \"p95\": " + num(s.p95) + ", \"max\": " + num(s.max) + "}";
}

/// Statistics of a signed sample: also its minimum.
std::string signed_stats_json(const Stats& s) {
  return stats_json(s).insert(1, "\"min\": " + num(s.min) + ", ");
}

}  // namespace

std::string metrics_json(const EvalMetrics& m, const std::string& command) {
  std::ostringstream j;
  j << "{\n";
  j << "  \"command\": \"" << esc(command) << "\",\n";
  j << "  \"scenes\": " << m.scenes << ",\n";
  j << "  \"books_targeted\": " << m.books_targeted << ",\n";
  j << "  \"books_moved\": " << m.books_moved << ",\n";
  j << "  \"books_moved_rate\": " << rate(m.books_moved, m.books_targeted) << ",\n";
  j << "  \"books_handed_over\": " << m.books_handed_over << ",\n";
  j << "  \"books_handed_over_unplaceable\": " << m.books_handed_over_unplaceable << ",\n";
  j << "  \"books_passed_over_not_standing\": " << m.books_passed_over_not_standing << ",\n";
  j << "  \"grasp_attempts\": " << m.grasp_attempts << ",\n";
  j << "  \"grasp_successes\": " << m.grasp_successes << ",\n";
  j << "  \"grasp_success_rate\": " << rate(m.grasp_successes, m.grasp_attempts) << ",\n";
  j << "  \"books_carried_along\": " << m.books_carried_along << ",\n";
  j << "  \"untargeted_books_off_the_upper_shelf\": " << m.untargeted_books_off_the_upper_shelf << ",\n";
  j << "  \"holder_releases\": " << m.holder_releases << ",\n";
  j << "  \"holder_placed_rate\": " << rate(m.holder_placed, m.holder_releases) << ",\n";
  j << "  \"holder_standing_rate\": " << rate(m.holder_standing, m.holder_retreats) << ",\n";
  j << "  \"books_upright_checked\": " << m.books_upright_checked << ",\n";
  j << "  \"books_upright_on_lower_shelf\": " << m.books_upright_on_lower_shelf << ",\n";
  j << "  \"books_upright_rate\": " << rate(m.books_upright_on_lower_shelf, m.books_upright_checked) << ",\n";
  j << "  \"p1_p2_decisions\": " << m.decisions << ",\n";
  j << "  \"p1_p2_agreement_rate\": " << rate(m.decisions_agreeing, m.decisions) << ",\n";
  j << "  \"p1_p2_disagreement_modes\": {";
  for (int k = 0; k < 4; ++k)
    j << (k ? ", " : "") << "\"" << kDisagreementModes[k] << "\": " << m.p1_p2_disagreements[k];
  j << "},\n";
  j << "  \"widths_measured\": " << m.widths << ",\n";
  j << "  \"width_within_1cm_rate\": " << rate(m.widths_within, m.widths) << ",\n";
  j << "  \"width_error_mm\": " << stats_json(stats_of(m.width_error_mm)) << ",\n";
  j << "  \"p1_error_mm\": {\"x\": " << stats_json(stats_of(m.p1_error_mm[0]))
    << ", \"y\": " << stats_json(stats_of(m.p1_error_mm[1])) << ", \"z\": " << stats_json(stats_of(m.p1_error_mm[2]))
    << "},\n";
  j << "  \"gp_error_mm\": {\"x\": " << signed_stats_json(stats_of(m.gp_error_mm[0]))
    << ", \"y\": " << signed_stats_json(stats_of(m.gp_error_mm[1]))
    << ", \"z\": " << signed_stats_json(stats_of(m.gp_error_mm[2])) << "},\n";
  j << "  \"gp_base_error_mm\": {\"x\": " << signed_stats_json(stats_of(m.gp_base_error_mm[0]))
    << ", \"y\": " << signed_stats_json(stats_of(m.gp_base_error_mm[1]))
    << ", \"z\": " << signed_stats_json(stats_of(m.gp_base_error_mm[2])) << "},\n";
  j << "  \"stripes_measured\": " << m.stripes << ",\n";
  j << "  \"stripe_within_tolerance_rate\": " << rate(m.stripes_within, m.stripes) << ",\n";
  j << "  \"stripe_error_mm\": {\"x\": " << signed_stats_json(stats_of(m.stripe_error_mm[0]))
    << ", \"y\": " << signed_stats_json(stats_of(m.stripe_error_mm[1])) << "},\n";
  j << "  \"plates_over_fore_edge_mm\": {";
  for (int k = 0; k < 4; ++k)
    j << (k ? ", " : "") << "\"" << kCloseOutcomes[k]
      << "\": " << signed_stats_json(stats_of(m.plates_over_fore_edge_mm[k]));
  j << "},\n";
  j << "  \"cycle_s\": " << stats_json(stats_of(m.cycle_s)) << ",\n";
  j << "  \"planning_ms\": " << stats_json(stats_of(m.plan_ms)) << ",\n";
  j << "  \"scene_wall_s\": " << stats_json(stats_of(m.scene_wall_s)) << ",\n";
  j << "  \"failure_modes\": {";
  bool first = true;
  for (const auto& [k, v] : m.failure_modes) {
    j << (first ? "" : ", ") << "\"" << esc(k) << "\": " << v;
    first = false;
  }
  j << "},\n";
  j << "  \"shortfall_seeds\": {";
  first = true;
  for (const auto& [kind, seeds] : m.shortfall_seeds) {
    j << (first ? "" : ", ") << "\"" << esc(kind) << "\": [";
    for (size_t i = 0; i < seeds.size(); ++i) j << (i ? ", " : "") << seeds[i];
    j << "]";
    first = false;
  }
  j << "},\n";
  j << "  \"failures\": [";
  first = true;
  for (const auto& [seed, why] : m.failures) {
    j << (first ? "\n" : ",\n") << "    {\"seed\": " << seed << ", \"reason\": \"" << esc(why) << "\"}";
    first = false;
  }
  j << (m.failures.empty() ? "]\n" : "\n  ]\n");
  j << "}\n";
  return j.str();
}

}  // namespace bookgrasp
