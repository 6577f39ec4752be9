// PlanningScene: FCL checks of the URDF primitives against hand-placed boxes,
// margins, the attached book and the allowed-collision matrix.
#include "services/planner/planning_scene.h"

#include <random>

#include <gtest/gtest.h>

namespace bookgrasp {
namespace {

const std::string kUrdf = std::string(BOOKGRASP_SOURCE_DIR) + "/config/robot/lwa3_pg70.urdf";

PlanningScene make_scene(double margin = 0.02) {
  PlanningSceneParams p;
  p.environment_margin_m = margin;
  p.self_margin_m = 0.005;
  p.finger_position_m = 0.0301;
  p.allowed_collisions = {{"gripper_finger_left", "gripper_finger_right"}, {"hand_camera", "gripper_palm"},
                          {"hand_camera", "gripper_finger_left"}, {"hand_camera", "gripper_finger_right"},
                          {"arm_6_link", "gripper_palm"}, {"base", "arm_2_link"}, {"arm_2_link", "arm_4_link"},
                          {"arm_4_link", "arm_6_link"}};
  return PlanningScene(ArmKinematics::from_urdf_file(kUrdf, "base", "gripper"), p);
}

SceneBox box(const std::string& name, const Eigen::Vector3d& centre, const Eigen::Vector3d& size) {
  SceneBox b;
  b.name = name;
  b.pose.translation() = centre;
  b.size = size;
  return b;
}

const Eigen::VectorXd kZero = Eigen::VectorXd::Zero(7);

TEST(PlanningScene, StraightUpArmIsFreeInAnEmptyWorld) {
  const PlanningScene s = make_scene();
  EXPECT_TRUE(s.is_valid(kZero));
  EXPECT_FALSE(s.check(kZero).collision);
}

// At all-zero joints the fingers reach from z = 1.1672 + 0.0789 to + 0.1389 (URDF), i.e. up to z = 1.3061.
TEST(PlanningScene, BoxOverTheFingertipsCollidesWithTheFingerOrPalm) {
  PlanningScene s = make_scene(0.0);
  s.set_environment({box("lid", {0, 0, 1.30}, {0.3, 0.3, 0.02})});  // spans z 1.29 .. 1.31
  const CollisionReport r = s.check(kZero);
  ASSERT_TRUE(r.collision);
  EXPECT_EQ(r.second, "lid");
  EXPECT_TRUE(r.first == "gripper_finger_left" || r.first == "gripper_finger_right") << r.first;
}

TEST(PlanningScene, MarginMakesNearMissesInvalid) {
  // Lid bottom 1 cm above the fingertips (z = 1.3061): free exactly, in collision with a 2 cm margin.
  PlanningScene s = make_scene(0.02);
  s.set_environment({box("lid", {0, 0, 1.3161 + 0.01}, {0.3, 0.3, 0.02})});
  EXPECT_FALSE(s.check(kZero, false).collision);
  EXPECT_TRUE(s.check(kZero, true).collision);
  EXPECT_FALSE(s.is_valid(kZero));
  // 3 cm above: free with the 2 cm margin.
  s.set_environment({box("lid", {0, 0, 1.3061 + 0.03 + 0.01}, {0.3, 0.3, 0.02})});
  EXPECT_TRUE(s.is_valid(kZero));
}

TEST(PlanningScene, ElbowAgainstAWall) {
  // Joint 4 at +pi/2 puts the forearm horizontal along +x at the elbow height z = 0.658 (URDF);
  // a wall at x = 0.4 .. 0.5 crossing that height is hit by a forearm link.
  PlanningScene s = make_scene(0.0);
  s.set_environment({box("wall", {0.45, 0, 0.658}, {0.1, 1.0, 0.2})});
  Eigen::VectorXd q = kZero;
  q[3] = 1.5707963;
  const CollisionReport r = s.check(q);
  ASSERT_TRUE(r.collision);
  EXPECT_EQ(r.second, "wall");
  EXPECT_TRUE(r.first == "arm_4_link" || r.first == "arm_5_link" || r.first == "arm_6_link") << r.first;
  EXPECT_TRUE(s.is_valid(kZero));  // straight up it is clear of the wall
}

TEST(PlanningScene, AttachedBookCollidesAndDetaches) {
  PlanningScene s = make_scene(0.0);
  // A book held above the gripper: box 0.2 m long along the approach (z) from the TCP (z = 1.2761).
  AttachedBox book;
  book.size = Eigen::Vector3d(0.15, 0.02, 0.2);
  book.pose_in_tip.translation() = Eigen::Vector3d(0, 0, 0.1);
  book.touch_links = {"gripper_palm", "gripper_finger_left", "gripper_finger_right"};
  s.set_environment({box("ceiling", {0, 0, 1.45}, {0.5, 0.5, 0.02})});  // 1.44 .. 1.46
  EXPECT_TRUE(s.is_valid(kZero));
  s.attach(book);  // book reaches z = 1.4761
  const CollisionReport r = s.check(kZero);
  ASSERT_TRUE(r.collision);
  EXPECT_EQ(r.first, "held_book");
  EXPECT_EQ(r.second, "ceiling");
  s.detach();
  EXPECT_TRUE(s.is_valid(kZero));
  // The book between the fingers is allowed to touch them.
  s.set_environment({});
  s.attach(book);
  EXPECT_TRUE(s.is_valid(kZero));
}

TEST(PlanningScene, AHeldBookKeepsItsOwnSmallerMargin) {
  // The book reaches z = 1.4761; a ceiling 12 mm above it is within the scene's 2 cm but outside the book's 8 mm.
  PlanningScene s = make_scene(0.02);
  AttachedBox book;
  book.size = Eigen::Vector3d(0.15, 0.02, 0.2);
  book.pose_in_tip.translation() = Eigen::Vector3d(0, 0, 0.1);
  book.touch_links = {"gripper_palm", "gripper_finger_left", "gripper_finger_right"};
  s.set_environment({box("ceiling", {0, 0, 1.4761 + 0.012 + 0.01}, {0.5, 0.5, 0.02})});
  s.attach(book);
  const CollisionReport r = s.check(kZero);
  ASSERT_TRUE(r.collision);
  EXPECT_EQ(r.first, "held_book");
  book.environment_margin_m = 0.008;
  s.attach(book);
  EXPECT_TRUE(s.is_valid(kZero)) << s.check(kZero).first << " / " << s.check(kZero).second;
  book.environment_margin_m = 0.05;  // never more than the scene's (its prefilter uses the scene's)
  s.attach(book);
  EXPECT_EQ(s.check(kZero).first, "held_book");
  s.set_environment({box("ceiling", {0, 0, 1.4761 + 0.03 + 0.01}, {0.5, 0.5, 0.02})});
  EXPECT_TRUE(s.is_valid(kZero));
}

TEST(PlanningScene, AdjacentLinksAndFingersAreAllowed) {
  const PlanningScene s = make_scene();
  const auto pairs = s.allowed_pairs();
  auto has = [&](const std::string& a, const std::string& b) {
    for (const auto& p : pairs)
      if ((p.first == a && p.second == b) || (p.first == b && p.second == a)) return true;
    return false;
  };
  EXPECT_TRUE(has("arm_1_link", "arm_2_link"));
  EXPECT_TRUE(has("arm_7_link", "gripper_palm"));  // through the geometry-less flange
  EXPECT_TRUE(has("gripper_palm", "gripper_finger_left"));
  EXPECT_TRUE(has("gripper_finger_left", "gripper_finger_right"));
  EXPECT_FALSE(has("arm_2_link", "gripper_palm"));
  // Random strongly folded configurations: self collisions are never between allowed pairs.
  std::mt19937 rng(3);
  const ArmKinematics& k = s.kinematics();
  std::uniform_real_distribution<double> u(0, 1), fold(1.3, 1.97);
  int self = 0;
  for (int i = 0; i < 3000; ++i) {
    Eigen::VectorXd q(7);
    for (int j = 0; j < 7; ++j) q[j] = k.lower_limits()[j] + u(rng) * (k.upper_limits()[j] - k.lower_limits()[j]);
    for (int j : {1, 3, 5}) q[j] = (u(rng) < 0.5 ? -1 : 1) * fold(rng);
    const CollisionReport r = s.check(q);
    if (!r.collision) continue;
    ++self;
    EXPECT_FALSE(has(r.first, r.second)) << r.describe();
  }
  EXPECT_GT(self, 0);  // folding the arm onto itself is caught
}

TEST(PlanningScene, FoldedArmOntoItselfIsSelfCollision) {
  // Shoulder tipped forward (q2 = 1.5), elbow folded back fully (q4 = -1.97), wrist folded (q6 = -1.97):
  // the hand comes back to the upper arm.
  const PlanningScene s = make_scene();
  Eigen::VectorXd q = kZero;
  q[1] = 1.5;
  q[3] = -1.97;
  q[5] = -1.97;
  const CollisionReport r = s.check(q);
  EXPECT_TRUE(r.collision) << "expected a self collision";
}

TEST(PlanningScene, RejectsBadBoxesAndLinks) {
  PlanningScene s = make_scene();
  EXPECT_THROW(s.set_environment({box("flat", {0, 0, 0}, {0.1, 0.0, 0.1})}), std::invalid_argument);
  EXPECT_THROW(s.set_environment({box("nan", {NAN, 0, 0}, {0.1, 0.1, 0.1})}), std::invalid_argument);
  AttachedBox b;
  b.size = Eigen::Vector3d(0.1, 0.1, 0.1);
  b.touch_links = {"no_such_link"};
  EXPECT_THROW(s.attach(b), std::invalid_argument);
  PlanningSceneParams p;
  p.allowed_collisions = {{"base", "nope"}};
  EXPECT_THROW(PlanningScene(ArmKinematics::from_urdf_file(kUrdf, "base", "gripper"), p), std::invalid_argument);
  EXPECT_FALSE(s.is_valid(Eigen::VectorXd::Constant(7, 3.5)));  // outside the joint limits
}

}  // namespace
}  // namespace bookgrasp
