#include "services/arbiter/combination_strategy.h"

#include <cmath>
#include <cstdio>

namespace bookgrasp {
namespace {

std::string mm(double metres) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.1f mm", metres * 1000.0);
  return buf;
}

/// The rule name of the step that starts BwH from an invalid P1 right of a measured PS.
constexpr const char* kP1RightOfMeasuredPs = "P1 right of the measured PS";

ValidationStep step(std::string rule, double value, double tol, bool passed, std::string decision) {
  return ValidationStep{std::move(rule), value, tol, passed, std::move(decision)};
}

CombinationResult fail(CombinationResult r, const std::string& rule, const std::string& why) {
  r.outcome = GraspOutcome::kNoGrasp;
  r.steps.push_back(step(rule, NAN, NAN, false, why));
  return r;
}

}  // namespace

std::string outcome_name(GraspOutcome o) {
  switch (o) {
    case GraspOutcome::kGrasp: return "GRASP";
    case GraspOutcome::kNextRegion: return "NEXT_REGION";
    case GraspOutcome::kP1LedAstray:
      return "P1_LED_ASTRAY";
    case GraspOutcome::kRaiseBwhStart:
      return "RAISE_BWH_START";
    case GraspOutcome::kStartFromP1:
      return "START_FROM_P1";
    case GraspOutcome::kNoGrasp: return "NO_GRASP";
  }
  return "?";
}

std::optional<double> front_depth_without_p1(const CombinationInputs& in, const CombinationTolerances& tol,
                                             ValidationStep* out) {
  const bool model = in.front_z_fallback && std::isfinite(*in.front_z_fallback);
  auto near_model = [&](double z) {
    return model && std::isfinite(z) && std::abs(z - *in.front_z_fallback) <= tol.invalid_p1_depth_range;
  };
  if (in.stereo_front_z && near_model(*in.stereo_front_z)) {
    *out = step("GP.z", *in.stereo_front_z - *in.front_z_fallback, tol.invalid_p1_depth_range, true,
                "no valid P1: GP.z from the stereo plane just left of PS (the target's front, pushed back or not)");
    return *in.stereo_front_z;
  }
  if (in.earlier_corner_z && near_model(*in.earlier_corner_z)) {
    *out = step("GP.z", *in.earlier_corner_z - *in.front_z_fallback, tol.invalid_p1_depth_range, true,
                "no valid P1: GP.z from R's depth the corner servo triangulated at this PS in an earlier attempt");
    return *in.earlier_corner_z;
  }
  if (in.p1 && in.p1->allFinite() && near_model(in.p1->z())) {
    *out = step("GP.z", in.p1->z() - *in.front_z_fallback, tol.invalid_p1_depth_range, true,
                "P1 invalid in Y: GP.z = P1.z (its front stands as deep as the target's, not the cart model's plane)");
    return in.p1->z();
  }
  if (model) {
    *out = step("GP.z", 0.0, 0.0, true, "no valid P1: GP.z from the cart model's book-front plane");
    return *in.front_z_fallback;
  }
  *out = step("GP.z", NAN, NAN, false, "no valid P1 and no book-front plane from the cart model: GP.z unknown");
  return std::nullopt;
}

namespace {

// P1.y - PS.y as the decision judges it: the check's when BwH started from it (CombinationInputs::
// p1_ps_dy_at_bwh_start), else from p1 and ps. `in.p1` must be set.
double p1_ps_dy(const CombinationInputs& in) {
  return in.p1_ps_dy_at_bwh_start.value_or(in.p1->y() - in.ps.y());
}

// Section 3.1 as the paper writes it (with P1_LED_ASTRAY's exception).
CombinationResult validate_p1_against_ps(const CombinationInputs& in, const CombinationTolerances& tol) {
  CombinationResult r;
  r.bwh_start = in.ps;
  if (!in.ps.allFinite()) return fail(r, "inputs", "PS is not finite: no reference for the right-most book");
  r.bwh_start.z() = front_depth_without_p1(in, tol, &r.front_depth_step).value_or(NAN);  // P1.z when P1 is valid
  if (!in.p1) {
    r.steps.push_back(step("P1.y vs PS.y", NAN, tol.p1_ps_y, false, "no P1 from BwS: ignore BwS, BwH starts from PS"));
    return r;
  }
  if (!in.p1->allFinite()) {
    r.steps.push_back(step("P1.y vs PS.y", NAN, tol.p1_ps_y, false, "P1 is not finite: ignore BwS, BwH starts from PS"));
    return r;
  }
  const double d = p1_ps_dy(in);
  if (in.p1_led_astray) {
    r.steps.push_back(step("P1 led BwH astray", d, tol.p1_ps_y, false,
                           "P1 (" + mm(d) +
                               " from PS) led BwH to a left neighbour's corner at this PS before: "
                               "ignore BwS, BwH starts from PS"));
    return r;
  }
  if (in.p1_between && tol.invalid_p1_over_p2 && d < -tol.p1_ps_y) {
    r.p1_valid = true;
    r.bwh_start = *in.p1;
    r.steps.push_back(step("P1 between P2 and PS", d, tol.p1_ps_y, true,
                           "P1 (" + mm(d) +
                               " from PS) stood between PS and a neighbour's corner at this PS before: its book is "
                               "the right-most, leaning left; BwH starts from P1"));
    return r;
  }
  if (std::abs(d) <= tol.p1_ps_y) {
    r.p1_valid = true;
    r.bwh_start = *in.p1;
    r.steps.push_back(step("P1.y vs PS.y", d, tol.p1_ps_y, true, "P1 valid: BwH starts from P1"));
  } else if (tol.start_from_p1_right_of_measured_ps && in.ps_measured && d > tol.p1_ps_y) {
    if (in.p1_right_start_failed) {
      r.steps.push_back(step("P1 right of the measured PS, BwH from it failed", d, tol.p1_ps_y, false,
                             "P1 invalid (" + mm(d) +
                                 " right of the measured stripe end), and BwH from it found no corner at this PS "
                                 "before (e.g. a book leaning on the side panel): BwH starts from PS"));
    } else {
      r.bwh_start.head<2>() = in.p1->head<2>();
      r.steps.push_back(step(kP1RightOfMeasuredPs, d, tol.p1_ps_y, false,
                             "P1 invalid (" + mm(d) +
                                 " right of the measured stripe end, where no book should stand: the stripe end was "
                                 "taken left of the right-most book's edge): BwH starts from P1"));
    }
  } else {
    r.steps.push_back(step("P1.y vs PS.y", d, tol.p1_ps_y, false,
                           "P1 invalid (" + mm(d) + " from PS, e.g. a thin book BwS missed): ignore BwS, BwH "
                           "starts from PS"));
  }
  return r;
}

}  // namespace

CombinationResult validate_p1(const CombinationInputs& in, const CombinationTolerances& tol) {
  CombinationResult r = validate_p1_against_ps(in, tol);
  if (in.p1_ps_dy_at_bwh_start && in.p1 && in.p1->allFinite() && in.ps.allFinite() && !r.steps.empty()) {
    const double now = in.p1->y() - in.ps.y();
    if (std::abs(*in.p1_ps_dy_at_bwh_start - now) > 5e-5)
      r.steps.back().decision +=
          " (P1 " + mm(*in.p1_ps_dy_at_bwh_start) + " from PS as when BwH started from it; now " + mm(now) + ")";
  }
  if (r.p1_valid || !in.bwh_start_raised || !(tol.raised_bwh_start_x > 0) || !r.bwh_start.allFinite()) return r;
  if (bwh_started_from_p1_right_of_ps(r)) return r;  // BwH does not start from PS
  const double ps_x = r.bwh_start.x();
  const bool over_corner = tol.raise_over_neighbour_corner && in.neighbour_corner_x &&
                           std::isfinite(*in.neighbour_corner_x) && *in.neighbour_corner_x > ps_x;
  r.bwh_start.x() = (over_corner ? *in.neighbour_corner_x : ps_x) + tol.raised_bwh_start_x;
  const std::string above =
      over_corner ? " above that corner (" + mm(r.bwh_start.x() - ps_x) + " above PS)" : " higher";
  r.steps.push_back(step("BwH start raised", r.bwh_start.x() - ps_x, tol.raised_bwh_start_x, true,
                         "BwH from PS found a shorter left neighbour's corner at this PS before: it starts " +
                             mm(tol.raised_bwh_start_x) + above + ", where a tall right-most book's corner lies"));
  return r;
}

bool bwh_started_from_p1_right_of_ps(const CombinationResult& r) {
  for (const ValidationStep& st : r.steps)
    if (st.rule == kP1RightOfMeasuredPs) return true;
  return false;
}

CombinationResult combine(const CombinationInputs& in, const CombinationTolerances& tol) {
  CombinationResult r = validate_p1(in, tol);
  if (r.outcome == GraspOutcome::kNoGrasp && !r.steps.empty() && r.steps.back().rule == "inputs") return r;
  if (!in.p2) return fail(r, "P2", "no P2: BwH servoing did not converge");
  if (!in.p2->allFinite()) return fail(r, "P2", "P2 is not finite");
  Eigen::Vector3d p2 = *in.p2;
  // Not in the paper: R located by the hand camera replaces P2.x (measured at R's depth) and gives GP.z.
  bool hand = false;
  if (tol.use_hand_corner && in.hand_corner) {
    const Eigen::Vector3d& h = *in.hand_corner;
    const double dy = h.y() - p2.y();
    const double dz = in.front_z_fallback ? h.z() - *in.front_z_fallback : 0.0;
    if (!h.allFinite()) {
      r.steps.push_back(step("hand corner", NAN, 0.0, false, "R's triangulation is not finite: not used"));
    } else if (std::abs(dy) > tol.hand_corner_max_y_from_p2) {
      r.steps.push_back(step("hand corner Y vs P2.y", dy, tol.hand_corner_max_y_from_p2, false,
                             "R triangulated " + mm(dy) + " from P2 in Y: not the corner the servo centred, not used"));
    } else if (tol.invalid_p1_depth_range > 0 && std::abs(dz) > tol.invalid_p1_depth_range) {
      r.steps.push_back(step("hand corner Z vs model front", dz, tol.invalid_p1_depth_range, false,
                             "R triangulated " + mm(dz) + " from the model's front plane: not used"));
    } else {
      hand = true;
      r.hand_corner_used = true;
      r.steps.push_back(step(
          "hand corner", dy, tol.hand_corner_max_y_from_p2, true,
          "R triangulated by the hand camera: P2.x " + mm(p2.x()) + " -> " + mm(h.x()) + " at its depth " + mm(h.z())));
      p2.x() = h.x();
    }
  }

  // The reference for P2: P1 when valid, else PS (the paper restarts BwH from PS).
  const Eigen::Vector3d ref = r.p1_valid ? *in.p1 : in.ps;
  const std::string ref_name = r.p1_valid ? "P1" : "PS";

  // Y (Section 3.2).
  double gp_y = p2.y();
  const double dy = p2.y() - ref.y();
  // Not in the paper: P2 left of a valid P1 beyond the Y tolerance *and* above it beyond the X
  // tolerance is a taller left neighbour's corner (each alone the paper accepts). P1, confirmed by
  // PS, is the right-most book's corner: grasp there. Not when the rule below (P2 far left of a measured PS) will
  // answer: P1 is confirmed by PS in Y only, and BwS's P1 can lie far up that neighbour's front (its "neighbour
  // climb", docs/BWS.md); GP = P1 then closed the plates above the book (far_cart seed 5125: P1 and GP 55 mm above
  // the corner, P2 22 mm left of PS). BwH from PS, the next attempt, finds the book's own corner.
  const bool p2_far_left_of_measured_ps =
      in.ps_measured && tol.p2_ps_y > 0 && p2.y() - in.ps.y() < -tol.p2_ps_y && !bwh_started_from_p1_right_of_ps(r);
  if (r.p1_valid && tol.p1_over_other_book && !p2_far_left_of_measured_ps) {
    const double dx = p2.x() - in.p1->x();
    if (dy <= -tol.y && dx >= tol.x) {
      r.steps.push_back(step(
          "P2 vs P1 (left and above)", dy, tol.y, false,
          "P2 is " + mm(-dy) + " left of and " + mm(dx) + " above P1: the corner of a taller left neighbour, GP = P1"));
      r.gp = *in.p1;
      r.steps.push_back(step("GP.z", 0.0, 0.0, true, "GP = P1 (GP.z = P1.z)"));
      r.outcome = GraspOutcome::kGrasp;
      return r;
    }
  }
  // Not in the paper: a measured PS is the right-most book's right edge within a few mm, so a P2 far left of it is a
  // left neighbour's corner. With a valid P1 it is the book P1 lay on, a taller neighbour of a thin right-most book
  // (P1_LED_ASTRAY: BwH from PS next). Without one, BwH from PS at the stripe's height centred a shorter neighbour's
  // corner, the tall right-most book's lying above the view (RAISE_BWH_START: BwH from higher next; once raised, no
  // grasp). It answers before the left-neighbour rule above when both apply. Not when BwH started
  // from an invalid P1 right of the measured PS: that PS is taken as off (far_cart seed 5498: the stripe end 202 mm
  // left of a book leaning on the side panel; raising from there sent BwH above every book).
  if (in.ps_measured && tol.p2_ps_y > 0 && (r.p1_valid || tol.raised_bwh_start_x > 0)) {
    const double dps = p2.y() - in.ps.y();
    if (dps < -tol.p2_ps_y && bwh_started_from_p1_right_of_ps(r)) {
      r.steps.push_back(step("P2.y vs measured PS.y", dps, tol.p2_ps_y, true,
                             "not checked: BwH started from P1 right of the measured PS, which is taken as off"));
    } else if (dps < -tol.p2_ps_y) {
      std::string why;
      if (r.p1_valid) {
        r.outcome = GraspOutcome::kP1LedAstray;
        why = "P2 is " + mm(-dps) +
              " left of the stripe end: P1 led BwH to a left neighbour's corner; the next attempt starts BwH from PS";
      } else if (in.bwh_start_raised) {
        r.outcome = GraspOutcome::kNoGrasp;
        why =
            "P2 is still " + mm(-dps) + " left of the stripe end from the raised start: a neighbour's corner, no grasp";
      } else {
        r.outcome = GraspOutcome::kRaiseBwhStart;
        why = "P2 is " + mm(-dps) +
              " left of the stripe end without a valid P1: a shorter left neighbour's corner; the next attempt starts "
              "BwH " +
              mm(tol.raised_bwh_start_x) + " higher";
      }
      r.steps.push_back(step("P2.y vs measured PS.y", dps, tol.p2_ps_y, false, why));
      return r;
    } else {
      r.steps.push_back(step("P2.y vs measured PS.y", dps, tol.p2_ps_y, true, "P2 at the stripe end's book"));
    }
  }
  // Not in the paper: an invalid P1 left of PS with P2 left of and below it: P1's (taller) book stands between P2's
  // and PS, so P2 is not the right-most book's corner (deployed demo, seed 1's fifth book: P1 on the 0.29 m right-most
  // book leaning left, 13 mm left of GP.y - BW; BwH from PS centred the 0.17 m neighbour's corner 30 mm left of P1).
  // START_FROM_P1; from that P1 (p1_between) such a P2 again gets no grasp. With a measured PS the rule above has
  // answered already (P2 would lie more than y + p1_ps_y left of PS).
  if (tol.invalid_p1_over_p2 && (!r.p1_valid || in.p1_between) && in.p1 && in.p1->allFinite() &&
      p1_ps_dy(in) < -tol.p1_ps_y) {
    const double dy1 = p2.y() - in.p1->y();
    const double dx1 = p2.x() - in.p1->x();
    if (dy1 <= -tol.y && dx1 <= -tol.x) {
      std::string why = "P2 is " + mm(-dy1) + " left of and " + mm(-dx1) + " below the P1 that lies " +
                        mm(-p1_ps_dy(in)) + " left of PS: P1's book stands between, P2 is a neighbour's corner";
      if (in.p1_between) {
        r.outcome = GraspOutcome::kNoGrasp;
        why += " (BwH from P1 too): no grasp";
      } else {
        r.outcome = GraspOutcome::kStartFromP1;
        why += "; the next attempt starts BwH from P1";
      }
      r.steps.push_back(step("P2 vs P1 left of PS (left and below)", dy1, tol.y, false, why));
      return r;
    }
  }

  if (std::abs(dy) < tol.y) {
    r.steps.push_back(step("P2.y vs " + ref_name + ".y", dy, tol.y, true, "P2.y valid: within the Y tolerance"));
  } else if (dy < 0) {
    r.steps.push_back(step("P2.y vs " + ref_name + ".y", dy, tol.y, true,
                           "P2.y valid: " + ref_name + " lies right of P2 and BwH already delivered the right-most "
                           "region"));
  } else if (!r.p1_valid && tol.p1_p2_agreement_over_ps && in.p1 && in.p1->allFinite() &&
             std::abs(p2.y() - in.p1->y()) < tol.y) {
    r.steps.push_back(step("P2.y vs P1.y (P1 failed the PS check)", p2.y() - in.p1->y(), tol.y, true,
                           "P2.y valid: " + mm(dy) +
                               " right of PS, but P1 agrees with it: both sensors put the book "
                               "right of where the last grasp left it (PS is stale)"));
  } else {
    const int next = in.p2_rank + 1;
    if (next >= tol.max_rank) {
      return fail(r, "P2.y vs " + ref_name + ".y",
                  "P2 lies " + mm(dy) + " right of " + ref_name + " on region " + std::to_string(in.p2_rank) +
                      " and no further region may be tried (max_rank " + std::to_string(tol.max_rank) + ")");
    }
    r.steps.push_back(step("P2.y vs " + ref_name + ".y", dy, tol.y, false,
                           "BwH chose a false region (P2 " + mm(dy) + " right of " + ref_name +
                               "): select the next region from the right (rank " + std::to_string(next) + ")"));
    r.outcome = GraspOutcome::kNextRegion;
    r.next_rank = next;
    return r;
  }

  // X (Section 3.2). Only P1 is a measurement of the book top; PS lies on the stripe.
  double gp_x = p2.x();
  if (r.p1_valid) {
    const double dx = p2.x() - in.p1->x();
    if (std::abs(dx) < tol.x) {
      r.steps.push_back(step("P2.x vs P1.x", dx, tol.x, true, "P2.x valid: within the X tolerance"));
    } else if (dx > 0) {
      r.steps.push_back(step("P2.x vs P1.x", dx, tol.x, true,
                             "P2.x valid: P2 above P1 (P1 from the point cloud cannot be above the real corner)"));
    } else {
      gp_x = in.p1->x();
      r.steps.push_back(step("P2.x vs P1.x", dx, tol.x, false, "P2 is " + mm(-dx) + " below P1: use P2.x = P1.x"));
    }
  } else {
    r.steps.push_back(step("P2.x vs P1.x", NAN, tol.x, true, "no valid P1: P2.x used as it is"));
  }

  // Z: GP.z = P1.z, or the book-front plane from the cart model without P1.
  double gp_z;
  if (hand) {
    gp_z = in.hand_corner->z();
    r.steps.push_back(step("GP.z", 0.0, 0.0, true, "GP.z = R's depth from the hand camera"));
  } else if (r.p1_valid) {
    gp_z = in.p1->z();
    r.steps.push_back(step("GP.z", 0.0, 0.0, true, "GP.z = P1.z"));
  } else {
    ValidationStep z_step;
    const std::optional<double> z = front_depth_without_p1(in, tol, &z_step);
    if (!z) return fail(r, z_step.rule, z_step.decision);
    gp_z = *z;
    r.steps.push_back(z_step);
  }

  r.gp = Eigen::Vector3d(gp_x, gp_y, gp_z);
  r.outcome = GraspOutcome::kGrasp;
  return r;
}

Eigen::Vector3d next_ps(const Eigen::Vector3d& ps, const Eigen::Vector3d& gp, double book_width) {
  return Eigen::Vector3d(ps.x(), gp.y() - book_width, ps.z());
}

ValidationStep check_book_width(double width, const BookSizeLimits& limits) {
  if (!std::isfinite(width) || width < 0)
    return step("book width", width, limits.s_max(), false, "book width is not a valid measurement");
  if (width > limits.s_max())
    return step("book width <= S_max", width, limits.s_max(), false,
                "book wider than S_max = L_max/2 - TCP offset (" + mm(limits.s_max()) +
                    "): the open left plate lands on the book itself");
  if (width < limits.s_min())
    return step("book width >= S_min", width, limits.s_min(), false,
                "book thinner than S_min = S_max/2 (" + mm(limits.s_min()) +
                    "): the left plate may reach the book after next");
  return step("S_min <= book width <= S_max", width, limits.s_max(), true, "admissible book width " + mm(width));
}

}  // namespace bookgrasp
