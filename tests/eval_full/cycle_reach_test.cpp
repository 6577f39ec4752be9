// Tests of services/eval_full/cycle_reach.h: the elbow bend a TCP pose forces, the true grasp frame,
// and the reachability of the cycle's poses, each against forward kinematics or the scene's truth.
#include "services/eval_full/cycle_reach.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "common/config.h"

namespace bookgrasp {
namespace {

const std::string kSrc = BOOKGRASP_SOURCE_DIR;

ArmKinematics arm() {
  return ArmKinematics::from_urdf_file(kSrc + "/config/robot/lwa3_pg70.urdf", "base", "gripper");
}

// The IK of bookgrasp_cycle_reach (24 restarts) and the park posture it starts from.
IkParams restarts_24() {
  IkParams p;
  p.max_restarts = 24;
  return p;
}
Eigen::VectorXd park_joints() {
  Eigen::VectorXd park(7);
  park << 0, -M_PI / 2, 0, -M_PI / 2, 0, -M_PI / 2, 0;
  return park;
}

CycleGeometry coordinator_geometry() {
  return CycleGeometry::from_config(Config::load_file(kSrc + "/config/services/coordinator.yaml").child("geometry"));
}

// The pose of the TCP fixes the elbow: for random postures within the limits, the bend computed from
// the TCP pose alone equals |arm_4| of the posture that produced it (whatever the other six joints).
TEST(CycleReach, ElbowBendFromTcpPoseEqualsTheJointThatMadeIt) {
  const ArmKinematics kin = arm();
  std::mt19937_64 rng(7);
  for (int i = 0; i < 200; ++i) {
    Eigen::VectorXd q(7);
    for (int j = 0; j < 7; ++j)
      q[j] = std::uniform_real_distribution<double>(kin.lower_limits()[j], kin.upper_limits()[j])(rng);
    const double bend = elbow_bend_for_tcp(kin, kin.tip_pose(q));
    ASSERT_TRUE(std::isfinite(bend)) << "posture " << i;
    EXPECT_NEAR(bend, std::abs(q[3]), 1e-6) << "posture " << i;
  }
}

TEST(CycleReach, ElbowBendIsNanOutOfTheArmsReach) {
  const ArmKinematics kin = arm();
  Eigen::Isometry3d far = Eigen::Isometry3d::Identity();
  far.translation() = Eigen::Vector3d(2.0, 0.0, 0.25);  // 2 m from the shoulder, the arm is ~1 m long
  EXPECT_TRUE(std::isnan(elbow_bend_for_tcp(kin, far)));
}

TEST(CycleReach, TrueGraspFrameHasXUpYRightZIntoTheShelf) {
  const scene::Scene scene = scene::load_scene(kSrc + "/config/scenes/default.yaml", 3);
  const Eigen::Isometry3d g = true_grasp_frame(scene);
  EXPECT_TRUE((g.translation() - scene.cart_pose.translation()).isZero(1e-12));
  EXPECT_TRUE(g.linear().isUnitary(1e-12));
  EXPECT_NEAR(g.linear().determinant(), 1.0, 1e-12);
  // Every book's P1 in the grasp frame: X = its top above the upper shelf, Z = just behind the shelf's
  // front edge (fore-edge offset of the scene, 0..2 cm, plus lean), inside the shelf's width.
  for (const scene::Book& b : scene.books) {
    const Eigen::Vector3d p1 =
        g.inverse() * scene::book_corners(b.pose, b.width_m, b.height_m, b.depth_m)[scene::kP1CornerIndex];
    EXPECT_NEAR(p1.x(), b.height_m, 0.02) << "book " << b.id;
    EXPECT_GT(p1.z(), -0.01) << "book " << b.id;
    EXPECT_LT(p1.z(), 0.04) << "book " << b.id;
    EXPECT_LT(std::abs(p1.y()), scene.shelf_width_m / 2) << "book " << b.id;
  }
}

// Every stage is checked with the arm's IK: a reachable stage has an IK posture whose forward
// kinematics is the stage's pose and whose elbow is the bend the pose needs; an unreachable one needs
// a bend beyond the limit (or out of reach) or the IK says why.
TEST(CycleReach, StagesAgreeWithForwardKinematicsAndTheElbowLimit) {
  const ArmKinematics kin = arm();
  const InverseKinematics ik(kin, restarts_24());
  const Eigen::VectorXd park = park_joints();
  const double limit = kin.upper_limits()[3];
  int reachable = 0, stages = 0;
  for (uint64_t seed = 1; seed <= 3; ++seed) {
    const scene::Scene scene = scene::load_scene(kSrc + "/config/scenes/default.yaml", seed);
    const std::vector<StageReach> r = cycle_reach(scene, coordinator_geometry(), ik, park);
    ASSERT_EQ(r.size(), 14u);
    EXPECT_EQ(r.front().stage, "stripe_start");
    EXPECT_EQ(r.back().stage, "lower_retreat");
    for (const StageReach& st : r) {
      ++stages;
      if (st.reachable) {
        ++reachable;
        const IkResult res = ik.solve(st.tcp, park);
        ASSERT_TRUE(res.success) << st.stage;
        EXPECT_LT((kin.tip_pose(res.q).translation() - st.tcp.translation()).norm(), 1e-3) << st.stage;
        EXPECT_NEAR(std::abs(res.q[3]), st.elbow_needed_rad, 1e-3) << st.stage;
        EXPECT_LE(st.elbow_needed_rad, limit + 1e-6) << st.stage;
      } else {
        EXPECT_FALSE(st.reason.empty()) << st.stage;
      }
    }
  }
  EXPECT_GT(reachable, 0) << "no stage of " << stages << " reachable: the check itself is suspect";
}

// The extraction at the shelf's right end (far_cart seeds 13, 14, 22: books 0.39-0.40 m right of the
// shoulder): straight up, the stretched arm does not reach the lift's end; the shipped diagonal lift
// (geometry.grasp.extract_lift_out_m) reaches it and the end of the extraction.
TEST(CycleReach, TheDiagonalLiftReachesTheRightEndsBooksTheStraightLiftDoesNot) {
  const ArmKinematics kin = arm();
  const InverseKinematics ik(kin, restarts_24());
  const Eigen::VectorXd park = park_joints();
  const CycleGeometry shipped = coordinator_geometry();
  ASSERT_GT(shipped.extract_lift_out, 0.0);
  CycleGeometry straight = shipped;
  straight.extract_lift_out = 0.0;
  const auto reach = [&](const std::vector<StageReach>& r, const std::string& stage) {
    for (const StageReach& st : r)
      if (st.stage == stage) return st.reachable;
    ADD_FAILURE() << "no stage " << stage;
    return false;
  };
  for (uint64_t seed : {13, 14, 22}) {
    const scene::Scene scene = scene::load_scene(kSrc + "/config/scenes/far_cart.yaml", seed);
    EXPECT_FALSE(reach(cycle_reach(scene, straight, ik, park), "extract_lift")) << "seed " << seed;
    const std::vector<StageReach> r = cycle_reach(scene, shipped, ik, park);
    EXPECT_TRUE(reach(r, "extract_lift")) << "seed " << seed;
    EXPECT_TRUE(reach(r, "extract_end")) << "seed " << seed;
  }
}

// A later book's cycle: its own corner, and its place on the lower shelf left of the books before it.
TEST(CycleReach, ALaterBooksCycleGraspsItAndPlacesItLeftOfTheEarlierOnes) {
  const InverseKinematics ik(arm(), IkParams{});
  Eigen::VectorXd park = Eigen::VectorXd::Zero(7);
  const scene::Scene scene = scene::load_scene(kSrc + "/config/scenes/far_cart.yaml", 2);
  ASSERT_GE(scene.books.size(), 3u);
  const CycleGeometry g = coordinator_geometry();
  const auto stage = [](const std::vector<StageReach>& r, const std::string& name) {
    for (const StageReach& st : r)
      if (st.stage == name) return st.tcp;
    ADD_FAILURE() << "no stage " << name;
    return Eigen::Isometry3d::Identity();
  };
  const std::vector<StageReach> first = cycle_reach(scene, g, ik, park, 0);
  const std::vector<StageReach> third = cycle_reach(scene, g, ik, park, 2);
  // The grasp is on the third book: its TCP lies (grasp Y, i.e. -base y) as far left of the first's as the books.
  const double books_apart = scene.books[2].pose.translation().y() - scene.books[0].pose.translation().y();
  EXPECT_GT(books_apart, 0.0);
  const double grasps_apart = stage(third, "grasp").translation().y() - stage(first, "grasp").translation().y();
  EXPECT_NEAR(grasps_apart, books_apart, 0.01);  // the covers' Y, not the centres': widths differ by < 2.5 cm / 2
  // Its lower-shelf place is left of the first's by the two earlier books' widths and gaps, plus half the width
  // difference (the TCP is at the book's middle).
  const double expect = scene.books[0].width_m + scene.books[1].width_m + 2 * g.lower_gap +
                        (scene.books[2].width_m - scene.books[0].width_m) / 2;
  EXPECT_NEAR(stage(third, "lower_place").translation().y() - stage(first, "lower_place").translation().y(), expect,
              1e-9);
  EXPECT_THROW(cycle_reach(scene, g, ik, park, scene.books.size()), std::runtime_error);
}

TEST(CycleReach, SceneWithoutBooksIsAClearError) {
  scene::Scene scene = scene::load_scene(kSrc + "/config/scenes/default.yaml", 1);
  scene.books.clear();
  const InverseKinematics ik(arm(), IkParams{});
  Eigen::VectorXd park = Eigen::VectorXd::Zero(7);
  try {
    cycle_reach(scene, coordinator_geometry(), ik, park);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no book"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace bookgrasp
