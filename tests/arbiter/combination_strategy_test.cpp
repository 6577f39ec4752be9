// Every branch of the combination strategy (paper Section 3) and the width limits (4.1), table-driven.
// Expected values are worked out by hand from the paper's rules; grasp frame: X up, Y right, Z into shelf.
#include "services/arbiter/combination_strategy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace bookgrasp {
namespace {

using V = Eigen::Vector3d;
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

struct Case {
  const char* name;
  std::optional<V> p1;
  V ps;
  std::optional<V> p2;
  int rank;
  std::optional<double> fallback_z;
  GraspOutcome outcome;
  bool p1_valid;
  V gp;          // checked when outcome == kGrasp
  int next_rank;  // checked when outcome == kNextRegion
  const char* last_decision_contains;
};

// Tolerances as in the paper: P1-PS 1 cm ("few millimetres"), Y 1.5 cm, X 2 cm.
const CombinationTolerances kTol{0.01, 0.015, 0.02, 3};
const V kPs(0.00, 0.100, 0.50);

// The cases as a table, two lines each.
// clang-format off
const Case kCases[] = {
    // P1 valid (0.5 cm from PS), P2 within both tolerances: GP = (P2.x, P2.y, P1.z).
    {"all_agree", V(0.10, 0.105, 0.40), kPs, V(0.11, 0.110, 0.45), 0, {}, GraspOutcome::kGrasp, true,
     V(0.11, 0.110, 0.40), 0, "GP.z = P1.z"},
    // P1 valid; P2 2 cm LEFT of P1 (dy = -0.02 < 0): P2.y accepted (BwH delivered the right-most region).
    {"p2_left_of_p1", V(0.10, 0.105, 0.40), kPs, V(0.10, 0.085, 0.45), 0, {}, GraspOutcome::kGrasp, true,
     V(0.10, 0.085, 0.40), 0, "GP.z = P1.z"},
    // P1 valid; P2 2 cm left of AND 3 cm above P1 (both beyond tolerance): a taller left neighbour, GP = P1.
    {"p2_left_and_above_p1", V(0.10, 0.105, 0.40), kPs, V(0.13, 0.085, 0.45), 0, {}, GraspOutcome::kGrasp, true,
     V(0.10, 0.105, 0.40), 0, "GP = P1"},
    // Left beyond the Y tolerance but only 1.9 cm above (within X): the paper's rules, GP from P2.
    {"p2_left_and_slightly_above_p1", V(0.10, 0.105, 0.40), kPs, V(0.119, 0.085, 0.45), 0, {}, GraspOutcome::kGrasp,
     true, V(0.119, 0.085, 0.40), 0, "GP.z = P1.z"},
    // 3 cm above but only 1.4 cm left (within Y): the paper's rules, GP from P2.
    {"p2_slightly_left_and_above_p1", V(0.10, 0.105, 0.40), kPs, V(0.13, 0.091, 0.45), 0, {}, GraspOutcome::kGrasp,
     true, V(0.13, 0.091, 0.40), 0, "GP.z = P1.z"},
    // Left and above a PS (P1 invalid): no measured corner to fall back on, the paper's rules.
    {"p1_invalid_p2_left_and_above", V(0.10, 0.080, 0.40), kPs, V(0.13, 0.080, 0.45), 0, 0.42, GraspOutcome::kGrasp,
     false, V(0.13, 0.080, 0.42), 0, "cart model"},
    // P1 valid; P2 2 cm RIGHT of P1: false region -> next region from the right (rank 1).
    {"p2_right_of_p1", V(0.10, 0.105, 0.40), kPs, V(0.10, 0.125, 0.45), 0, {}, GraspOutcome::kNextRegion, true,
     V::Zero(), 1, "next region"},
    // Same on rank 2 with max_rank 3: no region left.
    {"p2_right_no_more_regions", V(0.10, 0.105, 0.40), kPs, V(0.10, 0.125, 0.45), 2, {}, GraspOutcome::kNoGrasp,
     true, V::Zero(), 0, "no further region"},
    // X: P2 3 cm above P1 (dx = +0.03): P2.x accepted.
    {"p2_above_p1", V(0.10, 0.105, 0.40), kPs, V(0.13, 0.105, 0.45), 0, {}, GraspOutcome::kGrasp, true,
     V(0.13, 0.105, 0.40), 0, "GP.z = P1.z"},
    // X: P2 3 cm below P1 (dx = -0.03): P2.x = P1.x.
    {"p2_below_p1", V(0.10, 0.105, 0.40), kPs, V(0.07, 0.105, 0.45), 0, {}, GraspOutcome::kGrasp, true,
     V(0.10, 0.105, 0.40), 0, "GP.z = P1.z"},
    // X: 1.9 cm below is within the 2 cm tolerance: P2.x kept.
    {"p2_slightly_below_p1", V(0.10, 0.105, 0.40), kPs, V(0.081, 0.105, 0.45), 0, {}, GraspOutcome::kGrasp, true,
     V(0.081, 0.105, 0.40), 0, "GP.z = P1.z"},
    // P1 2 cm from PS (thin book missed by BwS): invalid; P2 checked against PS; Z from the cart model.
    {"p1_invalid_uses_ps", V(0.10, 0.080, 0.40), kPs, V(0.09, 0.095, 0.45), 0, 0.42, GraspOutcome::kGrasp, false,
     V(0.09, 0.095, 0.42), 0, "cart model"},
    // No P1 at all, P2 fine against PS, fallback Z given.
    {"no_p1", {}, kPs, V(0.09, 0.101, 0.45), 0, 0.41, GraspOutcome::kGrasp, false, V(0.09, 0.101, 0.41), 0,
     "cart model"},
    // P1 NaN is treated as missing.
    {"p1_nan", V(kNan, 0.1, 0.4), kPs, V(0.09, 0.101, 0.45), 0, 0.41, GraspOutcome::kGrasp, false,
     V(0.09, 0.101, 0.41), 0, "cart model"},
    // No valid P1 and no fallback Z: GP.z unknown.
    {"no_p1_no_fallback", {}, kPs, V(0.09, 0.101, 0.45), 0, {}, GraspOutcome::kNoGrasp, false, V::Zero(), 0,
     "GP.z unknown"},
    // No valid P1, P2 right of PS beyond tolerance: next region.
    {"no_p1_p2_right_of_ps", {}, kPs, V(0.09, 0.130, 0.45), 0, 0.41, GraspOutcome::kNextRegion, false, V::Zero(), 1,
     "next region"},
    // Not in the paper: P1 failed the PS check (7 cm right of it), P2 6.5 cm right of PS but 5 mm from P1: both
    // sensors see the book there; P2.y accepted, Z as without a valid P1 (the cart model here).
    {"p1_invalid_p2_agrees_right_of_ps", V(0.10, 0.170, 0.40), kPs, V(0.11, 0.165, 0.45), 0, 0.42,
     GraspOutcome::kGrasp, false, V(0.11, 0.165, 0.42), 0, "cart model"},
    // The same P2 with a P1 3.5 cm from it: no agreement, the paper's false region.
    {"p1_invalid_p2_right_of_ps_away_from_p1", V(0.10, 0.200, 0.40), kPs, V(0.11, 0.165, 0.45), 0, 0.42,
     GraspOutcome::kNextRegion, false, V::Zero(), 1, "next region"},
    // BwH failed: no P2.
    {"no_p2", V(0.10, 0.105, 0.40), kPs, {}, 0, {}, GraspOutcome::kNoGrasp, true, V::Zero(), 0, "did not converge"},
    {"p2_nan", V(0.10, 0.105, 0.40), kPs, V(0.1, kNan, 0.4), 0, {}, GraspOutcome::kNoGrasp, true, V::Zero(), 0,
     "not finite"},
    {"ps_nan", V(0.10, 0.105, 0.40), V(0, kNan, 0), V(0.1, 0.1, 0.4), 0, {}, GraspOutcome::kNoGrasp, false, V::Zero(),
     0, "PS is not finite"},
};

// clang-format on

class CombinationStrategy : public testing::TestWithParam<Case> {};

TEST_P(CombinationStrategy, Branch) {
  const Case& c = GetParam();
  CombinationInputs in;
  in.p1 = c.p1;
  in.ps = c.ps;
  in.p2 = c.p2;
  in.p2_rank = c.rank;
  in.front_z_fallback = c.fallback_z;
  const CombinationResult r = combine(in, kTol);
  EXPECT_EQ(outcome_name(r.outcome), outcome_name(c.outcome));
  EXPECT_EQ(r.p1_valid, c.p1_valid);
  if (c.outcome == GraspOutcome::kGrasp) {
    EXPECT_TRUE(r.gp.isApprox(c.gp, 1e-12)) << r.gp.transpose();
  }
  if (c.outcome == GraspOutcome::kNextRegion) {
    EXPECT_EQ(r.next_rank, c.next_rank);
  }
  ASSERT_FALSE(r.steps.empty());
  EXPECT_NE(r.steps.back().decision.find(c.last_decision_contains), std::string::npos) << r.steps.back().decision;
  // BwH starts from P1 when valid, else from PS (Section 3.1); its Z is the front depth the servo assumes, the
  // one GP.z takes.
  if (!c.ps.allFinite()) return;
  if (c.p1_valid) {
    EXPECT_TRUE(r.bwh_start.isApprox(*c.p1)) << r.bwh_start.transpose();
  } else {
    EXPECT_TRUE(r.bwh_start.head<2>().isApprox(c.ps.head<2>())) << r.bwh_start.transpose();
    if (c.outcome == GraspOutcome::kGrasp) {
      EXPECT_DOUBLE_EQ(r.bwh_start.z(), c.gp.z());
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Paper, CombinationStrategy, testing::ValuesIn(kCases),
                         [](const testing::TestParamInfo<Case>& i) { return std::string(i.param.name); });

/// P1, PS = kPs, P2 and the model's front plane for the switched-off rules below.
CombinationInputs corner_inputs(const V& p1, const V& p2, std::optional<double> front_z = {}) {
  CombinationInputs in;
  in.p1 = p1;
  in.ps = kPs;
  in.p2 = p2;
  in.front_z_fallback = front_z;
  return in;
}

TEST(CombinationStrategy, TheP1P2AgreementRuleCanBeSwitchedOffForThePapersRules) {
  CombinationTolerances paper = kTol;
  paper.p1_p2_agreement_over_ps = false;
  const CombinationInputs in = corner_inputs(V(0.10, 0.170, 0.40), V(0.11, 0.165, 0.45), 0.42);
  EXPECT_EQ(outcome_name(combine(in, kTol).outcome), outcome_name(GraspOutcome::kGrasp));
  const CombinationResult r = combine(in, paper);
  EXPECT_EQ(outcome_name(r.outcome), outcome_name(GraspOutcome::kNextRegion));
  EXPECT_EQ(r.next_rank, 1);
}

TEST(CombinationStrategy, TheLeftNeighbourRuleCanBeSwitchedOffForThePapersRules) {
  CombinationTolerances paper = kTol;
  paper.p1_over_other_book = false;
  const CombinationInputs in = corner_inputs(V(0.10, 0.105, 0.40), V(0.13, 0.085, 0.45));
  const CombinationResult r = combine(in, paper);
  EXPECT_EQ(r.outcome, GraspOutcome::kGrasp);
  EXPECT_TRUE(r.gp.isApprox(V(0.13, 0.085, 0.40), 1e-12)) << r.gp.transpose();
  const CombinationResult ours = combine(in, kTol);
  ASSERT_GE(ours.steps.size(), 2u);
  EXPECT_EQ(ours.steps[ours.steps.size() - 2].rule, "P2 vs P1 (left and above)");
  EXPECT_NEAR(ours.steps[ours.steps.size() - 2].value, -0.02, 1e-12);
}

/// `in` with its PS estimated (not measured), and with the measured-PS rule off (p2_ps_y 0): a GRASP at `gp`.
void expect_grasp_without_the_measured_ps_rule(const CombinationInputs& in, const CombinationTolerances& tol,
                                               const V& gp) {
  for (const bool measured : {false, true}) {
    CombinationInputs e = in;
    e.ps_measured = measured;
    CombinationTolerances t = tol;
    if (measured) t.p2_ps_y = 0.0;
    const CombinationResult g = combine(e, t);
    EXPECT_EQ(outcome_name(g.outcome), "GRASP") << "PS measured " << measured;
    EXPECT_TRUE(g.gp.isApprox(gp, 1e-12)) << "PS measured " << measured << ": " << g.gp.transpose();
  }
}

TEST(CombinationStrategy, AP2LeftAndAboveAP1FarLeftOfAMeasuredPsIsLedAstrayNotGpAtP1) {
  // Far_cart seed 5009 (grasp frame, m): the right-most corner at (0.1831, 0.2846); the stripe servo measured PS 0.3 mm
  // right of it; BwS's P1 climbed 56.8 mm up the taller left neighbour's front (valid: 7.8 mm left of the corner,
  // within 10 mm of PS); BwH from P1 centred the neighbour's corner 42.4 mm above and 17.6 mm left of P1, 25.7 mm left
  // of PS. GP = P1 closed the plates 57 mm above the book.
  CombinationTolerances tol = kTol;
  tol.p2_ps_y = 0.010;
  CombinationInputs in;
  in.ps = V(0.10, 0.2849, 0.50);
  in.ps_measured = true;
  in.p1 = V(0.2399, 0.2768, 0.40);
  in.p2 = V(0.2823, 0.2592, 0.45);
  const CombinationResult r = combine(in, tol);
  EXPECT_TRUE(r.p1_valid);
  EXPECT_EQ(outcome_name(r.outcome), "P1_LED_ASTRAY");
  ASSERT_FALSE(r.steps.empty());
  EXPECT_EQ(r.steps.back().rule, "P2.y vs measured PS.y");
  EXPECT_NEAR(r.steps.back().value, -0.0257, 1e-12);
  // A PS estimated from the last grasp (GP.y - BW) does not say where the book's edge is: GP = P1 as before. So with
  // the PS rule off.
  expect_grasp_without_the_measured_ps_rule(in, tol, *in.p1);
  // P2 left of and above P1 but within 10 mm of the measured PS: the left-neighbour rule still answers, GP = P1.
  in.p2 = V(0.2823, 0.2759, 0.45);  // 9.0 mm left of PS, 0.9 mm left of P1: not beyond the Y tolerance
  in.p1 = V(0.2399, 0.2910, 0.40);  // 6.1 mm right of PS (valid), so P2 is 15.1 mm left of P1
  const CombinationResult k = combine(in, tol);
  EXPECT_EQ(outcome_name(k.outcome), "GRASP");
  EXPECT_TRUE(k.gp.isApprox(*in.p1, 1e-12)) << k.gp.transpose();
}

/// PS, a P2 5 mm left of it and the model's front plane at Z 0.42, for the rules that give GP.z without a valid P1;
/// with `tol` ranging 0.15 around that plane (arbiter.yaml tolerances.invalid_p1_depth_range_m).
CombinationInputs depth_case(CombinationTolerances* tol) {
  *tol = kTol;
  tol->invalid_p1_depth_range = 0.15;
  CombinationInputs in;
  in.ps = kPs;
  in.p2 = V(0.09, 0.095, 0.45);
  in.front_z_fallback = 0.42;
  return in;
}

TEST(CombinationStrategy, AnInvalidP1NearTheModelsFrontGivesTheDepth) {
  CombinationTolerances tol;
  CombinationInputs in = depth_case(&tol);
  // P1 2 cm from PS (invalid in Y), 8 cm deeper than the model's plane: GP.z = P1.z; X and Y still from P2.
  in.p1 = V(0.10, 0.080, 0.50);
  CombinationResult r = combine(in, tol);
  ASSERT_EQ(outcome_name(r.outcome), outcome_name(GraspOutcome::kGrasp));
  EXPECT_FALSE(r.p1_valid);
  EXPECT_TRUE(r.gp.isApprox(V(0.09, 0.095, 0.50), 1e-12)) << r.gp.transpose();
  EXPECT_NE(r.steps.back().decision.find("GP.z = P1.z"), std::string::npos) << r.steps.back().decision;
  // 18 cm off the model's plane (beyond 0.15): not a book front the target can stand at, the model's plane.
  in.p1 = V(0.10, 0.080, 0.60);
  r = combine(in, tol);
  EXPECT_TRUE(r.gp.isApprox(V(0.09, 0.095, 0.42), 1e-12)) << r.gp.transpose();
  EXPECT_NE(r.steps.back().decision.find("cart model"), std::string::npos) << r.steps.back().decision;
  // The paper (range 0): the model's plane whatever P1 says.
  in.p1 = V(0.10, 0.080, 0.50);
  r = combine(in, kTol);
  EXPECT_TRUE(r.gp.isApprox(V(0.09, 0.095, 0.42), 1e-12)) << r.gp.transpose();
}

TEST(CombinationStrategy, TheStereoFrontLeftOfPsComesBeforeAnInvalidP1sDepth) {
  CombinationTolerances tol;
  CombinationInputs in = depth_case(&tol);
  in.p1 = V(0.10, 0.060, 0.43);  // 4 cm left of PS: an unpushed neighbour's corner
  in.stereo_front_z = 0.49;      // the target's front, pushed 7 cm back
  CombinationResult r = combine(in, tol);
  ASSERT_EQ(outcome_name(r.outcome), outcome_name(GraspOutcome::kGrasp));
  EXPECT_TRUE(r.gp.isApprox(V(0.09, 0.095, 0.49), 1e-12)) << r.gp.transpose();
  EXPECT_NE(r.steps.back().decision.find("stereo plane"), std::string::npos) << r.steps.back().decision;
  // The servo assumes the same depth before P2 exists.
  EXPECT_DOUBLE_EQ(validate_p1(in, tol).bwh_start.z(), 0.49);
  // Beyond the range of the model's plane it is not a book front: the invalid P1's depth is next.
  in.stereo_front_z = 0.58;
  r = combine(in, tol);
  EXPECT_TRUE(r.gp.isApprox(V(0.09, 0.095, 0.43), 1e-12)) << r.gp.transpose();
  // The paper's rule (range 0): the model's plane, for GP and the servo alike.
  in.stereo_front_z = 0.49;
  r = combine(in, kTol);
  EXPECT_TRUE(r.gp.isApprox(V(0.09, 0.095, 0.42), 1e-12)) << r.gp.transpose();
  EXPECT_DOUBLE_EQ(validate_p1(in, kTol).bwh_start.z(), 0.42);
  // No model plane and no usable depth: the servo's depth is unknown (NaN), and no grasp.
  in.front_z_fallback.reset();
  EXPECT_TRUE(std::isnan(validate_p1(in, tol).bwh_start.z()));
  EXPECT_EQ(outcome_name(combine(in, tol).outcome), outcome_name(GraspOutcome::kNoGrasp));
}

TEST(CombinationStrategy, AnEarlierAttemptsCornerDepthComesAfterTheStereoFrontAndBeforeAnInvalidP1s) {
  // The whole-shelf far_cart seed 1 book 7: pushed 13 cm deep by a failed insertion; no P1 near PS, no stereo front.
  CombinationTolerances tol;
  CombinationInputs in = depth_case(&tol);  // model plane 0.42, range 0.15
  in.p1 = V(0.10, 0.060, 0.43);             // an invalid P1 on a neighbour, at the model's depth
  in.earlier_corner_z = 0.55;               // R triangulated 13 cm behind the model's plane at the last attempt
  CombinationResult r = combine(in, tol);
  ASSERT_EQ(r.outcome, GraspOutcome::kGrasp);
  EXPECT_DOUBLE_EQ(r.gp.z(), 0.55);
  EXPECT_NE(r.steps.back().decision.find("earlier attempt"), std::string::npos) << r.steps.back().decision;
  EXPECT_DOUBLE_EQ(validate_p1(in, tol).bwh_start.z(), 0.55);  // the corner servo's standoff follows
  // A stereo front left of PS is a measurement of now: it comes first.
  in.stereo_front_z = 0.50;
  EXPECT_DOUBLE_EQ(validate_p1(in, tol).bwh_start.z(), 0.50);
  in.stereo_front_z.reset();
  // Beyond the range of the model's plane (0.42 + 0.15): not used; the invalid P1's depth is next.
  in.earlier_corner_z = 0.58;
  EXPECT_DOUBLE_EQ(validate_p1(in, tol).bwh_start.z(), 0.43);
  // A valid P1 gives the depth as in the paper, whatever was triangulated before.
  in.earlier_corner_z = 0.55;
  in.p1 = V(0.10, 0.103, 0.43);
  EXPECT_DOUBLE_EQ(validate_p1(in, tol).bwh_start.z(), 0.43);
}

TEST(CombinationStrategy, TheHandCornerGivesGpZAndP2XBeforeEveryOtherDepth) {
  CombinationTolerances tol;
  CombinationInputs in = depth_case(&tol);
  tol.use_hand_corner = true;
  tol.hand_corner_max_y_from_p2 = 0.01;
  in.p1 = V(0.10, 0.060, 0.43);  // invalid: 4 cm left of PS
  in.stereo_front_z = 0.49;
  // R triangulated 3 mm right of P2, 12 mm below it (the servo assumed a front too near), 9 cm deeper.
  in.hand_corner = V(0.078, 0.098, 0.51);
  CombinationResult r = combine(in, tol);
  ASSERT_EQ(outcome_name(r.outcome), outcome_name(GraspOutcome::kGrasp));
  EXPECT_TRUE(r.gp.isApprox(V(0.078, 0.095, 0.51), 1e-12)) << r.gp.transpose();  // Y stays P2's
  EXPECT_NE(r.steps.back().decision.find("hand camera"), std::string::npos) << r.steps.back().decision;
  // Also over a valid P1's depth (P1 at PS, 2 cm nearer than R), and P2.x at R's depth is checked against P1.x.
  in.p1 = V(0.080, 0.097, 0.49);
  r = combine(in, tol);
  EXPECT_TRUE(r.p1_valid);
  EXPECT_TRUE(r.gp.isApprox(V(0.078, 0.095, 0.51), 1e-12)) << r.gp.transpose();
  // The paper's X rule still applies to the measured P2.x: 3 cm below P1, GP.x = P1.x.
  in.hand_corner = V(0.050, 0.098, 0.51);
  r = combine(in, tol);
  EXPECT_TRUE(r.gp.isApprox(V(0.080, 0.095, 0.51), 1e-12)) << r.gp.transpose();
  in.p1.reset();
  // Refused, each with its reason, and the other depths take over (here the stereo front, 0.49):
  struct Refusal {
    Eigen::Vector3d corner;
    const char* words;
  };
  for (const Refusal& c : {Refusal{V(0.078, 0.110, 0.51), "from P2 in Y"},         // 15 mm right of P2
                           Refusal{V(0.078, 0.098, 0.60), "model's front plane"},  // 18 cm behind the model's front
                           Refusal{V(NAN, 0.098, 0.51), "not finite"}}) {
    in.hand_corner = c.corner;
    r = combine(in, tol);
    ASSERT_EQ(outcome_name(r.outcome), outcome_name(GraspOutcome::kGrasp)) << c.words;
    EXPECT_TRUE(r.gp.isApprox(V(0.09, 0.095, 0.49), 1e-12)) << c.words << ": " << r.gp.transpose();
    bool said = false;
    for (const ValidationStep& st : r.steps) said |= st.decision.find(c.words) != std::string::npos;
    EXPECT_TRUE(said) << c.words;
  }
  // Switched off (the paper): not used.
  in.hand_corner = V(0.078, 0.098, 0.51);
  tol.use_hand_corner = false;
  EXPECT_TRUE(combine(in, tol).gp.isApprox(V(0.09, 0.095, 0.49), 1e-12));
}

TEST(CombinationStrategy, P1ValidityBoundaryAndTrace) {
  CombinationInputs in;
  in.ps = kPs;
  in.p1 = V(0.1, 0.100 + 0.0099, 0.4);
  EXPECT_TRUE(validate_p1(in, kTol).p1_valid);
  in.p1 = V(0.1, 0.100 - 0.0101, 0.4);
  const auto r = validate_p1(in, kTol);
  EXPECT_FALSE(r.p1_valid);
  ASSERT_EQ(r.steps.size(), 1u);
  EXPECT_NEAR(r.steps[0].value, -0.0101, 1e-12);
  EXPECT_DOUBLE_EQ(r.steps[0].tolerance, 0.01);
}

// The decision judges P1 on P1.y - PS.y as the check that started BwH measured it, not as the frame moved since
// (far_cart seed 5021: 9.9 mm at the check, past 10 mm at the decision): both ways, and the step says so.
TEST(CombinationStrategy, P1IsJudgedOnTheDistanceTheCheckThatStartedBwhMeasured) {
  CombinationInputs in;
  in.ps = kPs;
  in.front_z_fallback = 0.42;
  in.p1 = V(0.1, 0.100 - 0.0101, 0.4);  // 10.1 mm left of PS now
  in.p1_ps_dy_at_bwh_start = -0.0099;   // 9.9 mm at the check
  CombinationResult r = validate_p1(in, kTol);
  EXPECT_TRUE(r.p1_valid);
  ASSERT_EQ(r.steps.size(), 1u);
  EXPECT_NEAR(r.steps[0].value, -0.0099, 1e-12);
  EXPECT_NE(r.steps[0].decision.find("(P1 -9.9 mm from PS as when BwH started from it; now -10.1 mm)"),
            std::string::npos)
      << r.steps[0].decision;
  // The whole decision too: P2 at P1's corner is grasped with GP.z = P1.z.
  in.p2 = V(0.1, 0.0899, 0.45);
  r = combine(in, kTol);
  EXPECT_EQ(r.outcome, GraspOutcome::kGrasp);
  EXPECT_TRUE(r.p1_valid);
  EXPECT_DOUBLE_EQ(r.gp.z(), 0.4);
  // The other way: invalid at the check, within the tolerance now: still invalid, BwH's start is PS.
  in.p2.reset();
  in.p1 = V(0.1, 0.100 - 0.0099, 0.4);
  in.p1_ps_dy_at_bwh_start = -0.0101;
  r = validate_p1(in, kTol);
  EXPECT_FALSE(r.p1_valid);
  EXPECT_DOUBLE_EQ(r.bwh_start.y(), kPs.y());
  // Equal to the distance now: no note.
  in.p1_ps_dy_at_bwh_start = -0.0099;
  r = validate_p1(in, kTol);
  EXPECT_TRUE(r.p1_valid);
  EXPECT_EQ(r.steps[0].decision.find("as when BwH started"), std::string::npos) << r.steps[0].decision;
}

TEST(CombinationStrategy, AP2FarLeftOfAMeasuredPsIsTheNeighbourP1LedBwhTo) {
  // A 12 mm right-most book, short, beside a taller one: the stripe servo measured PS at its right edge (Y 0.100);
  // BwS's P1 lay on the taller book 7 mm left (valid: within 10 mm of PS); BwH went from P1 to the taller book's
  // corner, 15 mm left of PS and 8 mm left of P1 (the paper accepts it in Y, within 1.5 cm of P1).
  CombinationTolerances tol = kTol;
  tol.p2_ps_y = 0.010;
  CombinationInputs in;
  in.ps = kPs;
  in.ps_measured = true;
  in.p1 = V(0.20, 0.093, 0.40);
  in.p2 = V(0.21, 0.085, 0.45);
  const CombinationResult r = combine(in, tol);
  EXPECT_EQ(r.outcome, GraspOutcome::kP1LedAstray);
  ASSERT_FALSE(r.steps.empty());
  EXPECT_EQ(r.steps.back().rule, "P2.y vs measured PS.y");
  EXPECT_NEAR(r.steps.back().value, -0.015, 1e-12);
  EXPECT_NE(r.steps.back().decision.find("the next attempt starts BwH from PS"), std::string::npos);
  EXPECT_EQ(outcome_name(r.outcome), "P1_LED_ASTRAY");
  // 9 mm left of PS: the book at the stripe end, grasped (GP = P2.x, P2.y, P1.z).
  in.p2 = V(0.21, 0.091, 0.45);
  EXPECT_EQ(combine(in, tol).outcome, GraspOutcome::kGrasp);
  EXPECT_TRUE(combine(in, tol).gp.isApprox(V(0.21, 0.091, 0.40), 1e-12));
  in.p2 = V(0.21, 0.085, 0.45);
  // A PS estimated from the last grasp (GP.y - BW), or the rule off: the paper's rules accept the P2.
  expect_grasp_without_the_measured_ps_rule(in, tol, V(0.21, 0.085, 0.40));
  // P2 left of AND above a P1 at the stripe end, 20 mm left of the measured PS: a taller neighbour's corner. Until stop
  // 41 the left-neighbour rule answered first with GP = P1; but P1 may have climbed that neighbour's front (seeds 5125,
  // 5009), so this rule answers first now: BwH from PS next.
  CombinationInputs taller = in;
  taller.p1 = V(0.20, 0.099, 0.40);
  taller.p2 = V(0.25, 0.080, 0.45);
  EXPECT_EQ(outcome_name(combine(taller, tol).outcome), "P1_LED_ASTRAY");
  // Without a valid P1 (BwH started from PS already) nothing led BwH astray: the paper's rule (P2 left of PS).
  CombinationInputs no_p1 = in;
  no_p1.p1.reset();
  no_p1.front_z_fallback = 0.42;
  EXPECT_EQ(combine(no_p1, tol).outcome, GraspOutcome::kGrasp);
  // The next attempt at the same PS: P1 is not used, BwH starts from PS.
  in.p1_led_astray = true;
  const CombinationResult check = validate_p1(in, tol);
  EXPECT_FALSE(check.p1_valid);
  EXPECT_TRUE(check.bwh_start.head<2>().isApprox(kPs.head<2>(), 1e-12));
  ASSERT_FALSE(check.steps.empty());
  EXPECT_EQ(check.steps.back().rule, "P1 led BwH astray");
}

TEST(CombinationStrategy, WithoutAValidP1AP2FarLeftOfAMeasuredPsRaisesTheNextBwhStart) {
  // A tall right-most book: BwS's P1 failed the PS check, BwH started from PS (Y 0.100) at the stripe's height and
  // centred the shorter left neighbour's corner 25 mm left of the measured PS (far_cart seed 5070's case).
  CombinationTolerances tol = kTol;
  tol.p2_ps_y = 0.010;
  tol.raised_bwh_start_x = 0.10;
  CombinationInputs in;
  in.ps = kPs;
  in.ps_measured = true;
  in.front_z_fallback = 0.42;
  in.p2 = V(0.12, 0.075, 0.45);
  const CombinationResult r = combine(in, tol);
  EXPECT_EQ(r.outcome, GraspOutcome::kRaiseBwhStart);
  EXPECT_EQ(outcome_name(r.outcome), "RAISE_BWH_START");
  ASSERT_FALSE(r.steps.empty());
  EXPECT_EQ(r.steps.back().rule, "P2.y vs measured PS.y");
  EXPECT_NEAR(r.steps.back().value, -0.025, 1e-12);
  EXPECT_NE(r.steps.back().decision.find("starts BwH 100.0 mm higher"), std::string::npos) << r.steps.back().decision;
  // An invalid P1 (on the shorter neighbour, 20 mm left of PS) changes nothing.
  CombinationInputs bad_p1 = in;
  bad_p1.p1 = V(0.11, 0.080, 0.40);
  EXPECT_EQ(combine(bad_p1, tol).outcome, GraspOutcome::kRaiseBwhStart);
  // A P2 9 mm left of PS is the book at the stripe end: grasped there.
  CombinationInputs near = in;
  near.p2 = V(0.12, 0.091, 0.45);
  EXPECT_EQ(combine(near, tol).outcome, GraspOutcome::kGrasp);
  // The rule off, or PS the estimate GP.y - BW: the paper's rule (P2 left of PS) grasps the neighbour's corner.
  CombinationTolerances off = tol;
  off.raised_bwh_start_x = 0.0;
  EXPECT_EQ(combine(in, off).outcome, GraspOutcome::kGrasp);
  CombinationInputs estimated = in;
  estimated.ps_measured = false;
  EXPECT_EQ(combine(estimated, tol).outcome, GraspOutcome::kGrasp);

  // The next attempt at the same PS: BwH starts from PS raised by 100 mm in X, same Y and depth.
  in.bwh_start_raised = true;
  const CombinationResult check = validate_p1(in, tol);
  EXPECT_FALSE(check.p1_valid);
  EXPECT_NEAR(check.bwh_start.x(), kPs.x() + 0.10, 1e-12);
  EXPECT_NEAR(check.bwh_start.y(), kPs.y(), 1e-12);
  EXPECT_NEAR(check.bwh_start.z(), 0.42, 1e-12);
  ASSERT_FALSE(check.steps.empty());
  EXPECT_EQ(check.steps.back().rule, "BwH start raised");
  // From there, the tall book's corner at the stripe end is grasped; a far-left P2 again gets no grasp (no second
  // raise: a failed attempt, far_cart seed 5302 once converged 72 mm left from the raised start).
  in.p2 = V(0.23, 0.098, 0.45);
  const CombinationResult tall = combine(in, tol);
  EXPECT_EQ(tall.outcome, GraspOutcome::kGrasp);
  EXPECT_TRUE(tall.gp.isApprox(V(0.23, 0.098, 0.42), 1e-12)) << tall.gp.transpose();
  in.p2 = V(0.12, 0.075, 0.45);
  const CombinationResult again = combine(in, tol);
  EXPECT_EQ(again.outcome, GraspOutcome::kNoGrasp);
  ASSERT_FALSE(again.steps.empty());
  EXPECT_NE(again.steps.back().decision.find("still 25.0 mm left of the stripe end from the raised start"),
            std::string::npos)
      << again.steps.back().decision;
  // A valid P1 never raises the start.
  CombinationInputs valid = in;
  valid.p1 = V(0.22, 0.099, 0.40);
  EXPECT_TRUE(validate_p1(valid, tol).bwh_start.isApprox(V(0.22, 0.099, 0.40), 1e-12));
}

TEST(CombinationStrategy, TheRaisedBwhStartLiesAboveTheNeighboursCornerBwhFound) {
  // Far_cart seed 5273: PS at the stripe's height, the 186 mm neighbour's corner BwH found 69 mm above it, the
  // 290 mm right-most book's corner 173 mm above it. PS + 100 mm left the tall corner out of view.
  CombinationTolerances tol = kTol;
  tol.p2_ps_y = 0.010;
  tol.raised_bwh_start_x = 0.10;
  CombinationInputs in;
  in.ps = kPs;  // X 0.00
  in.ps_measured = true;
  in.front_z_fallback = 0.42;
  in.bwh_start_raised = true;
  in.neighbour_corner_x = 0.069;
  const CombinationResult r = validate_p1(in, tol);
  EXPECT_NEAR(r.bwh_start.x(), 0.169, 1e-12);
  EXPECT_NEAR(r.bwh_start.y(), kPs.y(), 1e-12);
  EXPECT_NEAR(r.bwh_start.z(), 0.42, 1e-12);
  ASSERT_FALSE(r.steps.empty());
  EXPECT_EQ(r.steps.back().rule, "BwH start raised");
  EXPECT_NEAR(r.steps.back().value, 0.169, 1e-12);
  EXPECT_NE(r.steps.back().decision.find("100.0 mm above that corner (169.0 mm above PS)"), std::string::npos)
      << r.steps.back().decision;
  // The rule off: above PS (stop 28's start).
  CombinationTolerances off = tol;
  off.raise_over_neighbour_corner = false;
  EXPECT_NEAR(validate_p1(in, off).bwh_start.x(), 0.10, 1e-12);
  // A corner below PS, a non-finite one, or none: above PS.
  for (const std::optional<double>& x :
       {std::optional<double>(-0.02), std::optional<double>(NAN), std::optional<double>()}) {
    CombinationInputs other = in;
    other.neighbour_corner_x = x;
    const CombinationResult o = validate_p1(other, tol);
    EXPECT_NEAR(o.bwh_start.x(), 0.10, 1e-12);
    ASSERT_FALSE(o.steps.empty());
    EXPECT_NE(o.steps.back().decision.find("100.0 mm higher"), std::string::npos) << o.steps.back().decision;
  }
  // Not raised at this PS: the corner is not used.
  CombinationInputs not_raised = in;
  not_raised.bwh_start_raised = false;
  EXPECT_NEAR(validate_p1(not_raised, tol).bwh_start.x(), 0.0, 1e-12);
}

TEST(CombinationStrategy, AnInvalidP1RightOfAMeasuredPsStartsBwhFromP1) {
  // Far_cart seed 5282: the stripe end taken at a shadow above a short book, 69.7 mm left of the right-most corner;
  // P1 on the right-most book, 59 mm right of PS. The paper starts BwH from PS, which took a book further left.
  CombinationTolerances tol = kTol;
  tol.start_from_p1_right_of_measured_ps = true;
  CombinationInputs in;
  in.ps = kPs;  // (0.00, 0.100, 0.50)
  in.ps_measured = true;
  in.front_z_fallback = 0.42;
  in.p1 = V(0.257, 0.159, 0.41);
  const CombinationResult check = validate_p1(in, tol);
  EXPECT_FALSE(check.p1_valid);
  EXPECT_TRUE(check.bwh_start.isApprox(V(0.257, 0.159, 0.42), 1e-12)) << check.bwh_start.transpose();
  ASSERT_FALSE(check.steps.empty());
  EXPECT_EQ(check.steps.back().rule, "P1 right of the measured PS");
  EXPECT_NEAR(check.steps.back().value, 0.059, 1e-12);
  EXPECT_NE(check.steps.back().decision.find("59.0 mm right of the measured stripe end"), std::string::npos)
      << check.steps.back().decision;
  // BwH from P1 centres the right-most corner 11 mm right of P1: both sensors agree, grasped there (P1 stays
  // invalid: GP.z from the model's front plane).
  in.p2 = V(0.258, 0.170, 0.45);
  const CombinationResult r = combine(in, tol);
  EXPECT_EQ(r.outcome, GraspOutcome::kGrasp);
  EXPECT_TRUE(r.gp.isApprox(V(0.258, 0.170, 0.42), 1e-12)) << r.gp.transpose();
  EXPECT_TRUE(bwh_started_from_p1_right_of_ps(r));
  // From P1, BwH centred a corner 25 mm left of PS (seed 5498, a book leaning on the side panel): PS is taken as off,
  // so no raise (which assumes BwH started from PS); the paper's Y rule accepts it.
  CombinationTolerances raising = tol;
  raising.p2_ps_y = 0.010;
  raising.raised_bwh_start_x = 0.10;
  CombinationInputs left_of_ps = in;
  left_of_ps.p2 = V(0.12, 0.075, 0.45);
  const CombinationResult unchecked = combine(left_of_ps, raising);
  EXPECT_EQ(unchecked.outcome, GraspOutcome::kGrasp);
  bool skipped = false;
  for (const ValidationStep& st : unchecked.steps)
    skipped |= st.rule == "P2.y vs measured PS.y" && st.decision.find("not checked") != std::string::npos;
  EXPECT_TRUE(skipped);
  CombinationInputs from_ps_start = left_of_ps;
  from_ps_start.p1_right_start_failed = true;  // BwH from PS: the raise applies
  EXPECT_EQ(combine(from_ps_start, raising).outcome, GraspOutcome::kRaiseBwhStart);
  // BwH from P1 found no corner at this PS before (a book leaning on the side panel): from PS, the paper's start.
  CombinationInputs failed = in;
  failed.p1_right_start_failed = true;
  const CombinationResult back = validate_p1(failed, tol);
  EXPECT_FALSE(back.p1_valid);
  EXPECT_TRUE(back.bwh_start.isApprox(V(0.0, 0.100, 0.42), 1e-12)) << back.bwh_start.transpose();
  ASSERT_FALSE(back.steps.empty());
  EXPECT_EQ(back.steps.back().rule, "P1 right of the measured PS, BwH from it failed");
  EXPECT_FALSE(bwh_started_from_p1_right_of_ps(back));
  // A raised start at this PS does not move a start from P1.
  CombinationInputs raised = in;
  raised.bwh_start_raised = true;
  raised.neighbour_corner_x = 0.14;
  CombinationTolerances raise_tol = tol;
  raise_tol.p2_ps_y = 0.010;
  raise_tol.raised_bwh_start_x = 0.10;
  EXPECT_TRUE(validate_p1(raised, raise_tol).bwh_start.isApprox(V(0.257, 0.159, 0.42), 1e-12));
  // From PS: the rule off, PS the estimate GP.y - BW, or P1 left of PS (the paper's missed thin book).
  CombinationTolerances off = tol;
  off.start_from_p1_right_of_measured_ps = false;
  EXPECT_TRUE(validate_p1(in, off).bwh_start.isApprox(V(0.0, 0.100, 0.42), 1e-12));
  CombinationInputs estimated = in;
  estimated.ps_measured = false;
  EXPECT_TRUE(validate_p1(estimated, tol).bwh_start.isApprox(V(0.0, 0.100, 0.42), 1e-12));
  CombinationInputs left = in;
  left.p1 = V(0.257, 0.041, 0.41);
  const CombinationResult from_ps = validate_p1(left, tol);
  EXPECT_TRUE(from_ps.bwh_start.isApprox(V(0.0, 0.100, 0.42), 1e-12));
  ASSERT_FALSE(from_ps.steps.empty());
  EXPECT_EQ(from_ps.steps.back().rule, "P1.y vs PS.y");
  // Within p1_ps_y it is the paper's valid P1.
  CombinationInputs near = in;
  near.p1 = V(0.257, 0.108, 0.41);
  EXPECT_TRUE(validate_p1(near, tol).p1_valid);
}

TEST(CombinationStrategy, AP2LeftOfAndBelowAnInvalidP1OnItsLeftSendsBwhToThatP1AtAnyPs) {
  // Seed 1's fifth book (deployed demo, stop 30): PS = GP.y - BW after the fourth grasp (not measured). The 0.29 m
  // right-most book leans left: its corner P1 lies 13 mm left of PS (invalid). BwH from PS centred the 0.17 m
  // neighbour's corner 30 mm left of and 125 mm below P1; the paper's rules grasp it (P2 left of PS).
  CombinationTolerances tol = kTol;
  tol.invalid_p1_over_p2 = true;
  CombinationInputs in;
  in.ps = kPs;  // (0.00, 0.100, 0.50), the estimate
  in.front_z_fallback = 0.42;
  in.p1 = V(0.30, 0.087, 0.40);
  in.p2 = V(0.175, 0.057, 0.45);
  const CombinationResult r = combine(in, tol);
  EXPECT_EQ(outcome_name(r.outcome), "START_FROM_P1");
  ASSERT_FALSE(r.steps.empty());
  EXPECT_EQ(r.steps.back().rule, "P2 vs P1 left of PS (left and below)");
  EXPECT_NEAR(r.steps.back().value, -0.030, 1e-12);
  EXPECT_NE(r.steps.back().decision.find("30.0 mm left of and 125.0 mm below the P1 that lies 13.0 mm left of PS"),
            std::string::npos)
      << r.steps.back().decision;
  // The rule off: the paper's grasp at the neighbour's corner.
  CombinationTolerances off = tol;
  off.invalid_p1_over_p2 = false;
  EXPECT_EQ(combine(in, off).outcome, GraspOutcome::kGrasp);
  // Not this rule's (the paper's rules grasp): P2 at P1's book (left of PS by the lean, not below P1); P2 left of P1
  // but not below it by more than x (2 cm); P2 below P1 but within y (1.5 cm) of it in Y; P1 invalid on the right of
  // PS (not a book between P2 and PS).
  const struct {
    const char* name;
    V p1, p2;
  } kNotBetween[] = {{"same book", V(0.30, 0.087, 0.40), V(0.295, 0.088, 0.45)},
                     {"level", V(0.30, 0.087, 0.40), V(0.285, 0.057, 0.45)},
                     {"near in Y", V(0.30, 0.087, 0.40), V(0.175, 0.073, 0.45)},
                     {"P1 right of PS", V(0.30, 0.113, 0.40), V(0.175, 0.083, 0.45)}};
  for (const auto& k : kNotBetween) {
    CombinationInputs c = in;
    c.p1 = k.p1;
    c.p2 = k.p2;
    EXPECT_EQ(combine(c, tol).outcome, GraspOutcome::kGrasp) << k.name;
  }
  // A valid P1 (5 mm left of PS) is not this rule's: P2 left of and below it is grasped by the paper's Y rule.
  CombinationInputs valid = in;
  valid.p1 = V(0.30, 0.095, 0.40);
  const CombinationResult v = combine(valid, tol);
  EXPECT_EQ(v.outcome, GraspOutcome::kGrasp);
  EXPECT_TRUE(v.p1_valid);
  // A measured PS: the measured-PS rule answers first (P2 43 mm left of it; the tall book's corner lies above BwH's
  // view from PS, RAISE_BWH_START), as before this rule.
  CombinationTolerances measured_tol = tol;
  measured_tol.p2_ps_y = 0.010;
  measured_tol.raised_bwh_start_x = 0.10;
  CombinationInputs measured = in;
  measured.ps_measured = true;
  EXPECT_EQ(outcome_name(combine(measured, measured_tol).outcome), "RAISE_BWH_START");

  // The next check at the same PS: that P1 is taken as valid, BwH starts from it (its own depth).
  in.p1_between = true;
  const CombinationResult check = validate_p1(in, tol);
  EXPECT_TRUE(check.p1_valid);
  EXPECT_TRUE(check.bwh_start.isApprox(V(0.30, 0.087, 0.40), 1e-12)) << check.bwh_start.transpose();
  ASSERT_FALSE(check.steps.empty());
  EXPECT_EQ(check.steps.back().rule, "P1 between P2 and PS");
  // ... but not with the rule off, nor a P1 right of PS.
  EXPECT_FALSE(validate_p1(in, off).p1_valid);
  CombinationInputs right_between = in;
  right_between.p1 = V(0.30, 0.113, 0.40);
  right_between.p1_between = true;
  EXPECT_FALSE(validate_p1(right_between, tol).p1_valid);
  // From P1 the tall book's corner: GP there, GP.z = P1.z.
  in.p2 = V(0.298, 0.088, 0.45);
  const CombinationResult tall = combine(in, tol);
  EXPECT_EQ(tall.outcome, GraspOutcome::kGrasp);
  EXPECT_TRUE(tall.gp.isApprox(V(0.298, 0.088, 0.40), 1e-12)) << tall.gp.transpose();
  // From P1 the same neighbour's corner again: no grasp (not GP at P1.x over the neighbour).
  in.p2 = V(0.175, 0.057, 0.45);
  const CombinationResult again = combine(in, tol);
  EXPECT_EQ(again.outcome, GraspOutcome::kNoGrasp);
  ASSERT_FALSE(again.steps.empty());
  EXPECT_NE(again.steps.back().decision.find("(BwH from P1 too): no grasp"), std::string::npos)
      << again.steps.back().decision;
}

TEST(CombinationStrategy, NextPsAfterAGrasp) {
  // GP.y = 0.105, a 2.3 cm book: the next book's right edge is expected at 0.082.
  const V ps = next_ps(kPs, V(0.1, 0.105, 0.4), 0.023);
  EXPECT_NEAR(ps.y(), 0.082, 1e-12);
  EXPECT_DOUBLE_EQ(ps.x(), kPs.x());
  EXPECT_DOUBLE_EQ(ps.z(), kPs.z());
}

TEST(BookWidth, Section41Limits) {
  const BookSizeLimits lim{0.06};
  EXPECT_DOUBLE_EQ(lim.s_max(), 0.03);
  EXPECT_DOUBLE_EQ(lim.s_min(), 0.015);
  EXPECT_TRUE(check_book_width(0.02, lim).passed);
  EXPECT_TRUE(check_book_width(0.03, lim).passed);
  EXPECT_FALSE(check_book_width(0.031, lim).passed);
  EXPECT_NE(check_book_width(0.031, lim).decision.find("S_max"), std::string::npos);
  EXPECT_FALSE(check_book_width(0.012, lim).passed);
  EXPECT_NE(check_book_width(0.012, lim).decision.find("S_min"), std::string::npos);
  EXPECT_FALSE(check_book_width(kNan, lim).passed);
}

TEST(BookWidth, TheTcpOffsetMovesTheLeftPlateAndSoTheLimits) {
  // The gripper's middle 15 mm left of GP (into the book): the left plate lands 45 mm left of the right edge.
  const BookSizeLimits lim{0.06, -0.015};
  EXPECT_DOUBLE_EQ(lim.s_max(), 0.045);
  EXPECT_DOUBLE_EQ(lim.s_min(), 0.0225);
  EXPECT_TRUE(check_book_width(0.033, lim).passed);
  EXPECT_FALSE(check_book_width(0.046, lim).passed);
  EXPECT_FALSE(check_book_width(0.020, lim).passed);
}

}  // namespace
}  // namespace bookgrasp
