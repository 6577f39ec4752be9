// PlannerNode: requests as messages (good and bad), markers moving the scene,
// and the component on an in-process bus.
#include "services/planner/planner_node.h"

#include <gtest/gtest.h>

#include "common/composition.h"
#include "common/pose_conversion.h"

namespace bookgrasp {
namespace {

const std::string kConfig = std::string(BOOKGRASP_SOURCE_DIR) + "/config/services/planner.yaml";

plan_request_t joint_request(const std::vector<double>& start, const std::vector<double>& goal) {
  plan_request_t r;
  r.utime = 123456789;
  r.request_id = 42;
  r.planner = "";
  r.goal_type = plan_request_t::JOINTS;
  r.num_joints = static_cast<int32_t>(start.size());
  r.start_joints = start;
  r.goal_joints = goal;
  r.goal_pose = isometry_to_pose(Eigen::Isometry3d::Identity(), "base", "gripper", 0);
  r.position_tolerance_m = 0.001;
  r.orientation_tolerance_rad = 0.01;
  r.keep_orientation = false;
  r.time_budget_s = 1.0;
  r.holding_book = false;
  r.held_book_size_m[0] = r.held_book_size_m[1] = r.held_book_size_m[2] = 0.0;
  r.num_then_poses = 0;
  r.num_obstacles = 0;
  return r;
}

// Home of the simulation (config/scenes/default.yaml) and the arm raised in front of the cart.
const std::vector<double> kHome{2.0944, 1.309, 0.0, -1.9548, 0.0, -1.3963, 0.0};
const std::vector<double> kUp{0.0, 0.3, 0.0, 0.6, 0.0, 0.4, 0.0};

class PlannerNodeTest : public ::testing::Test {
 protected:
  PlannerNodeTest() : node_(PlannerSettings::load(kConfig)) {}
  PlannerNode node_;
};

TEST_F(PlannerNodeTest, GoodRequestGivesAFilledTrajectory) {
  const plan_result_t r = node_.process(joint_request(kHome, kUp));
  ASSERT_TRUE(r.success) << r.message;
  EXPECT_EQ(r.utime, 123456789);
  EXPECT_EQ(r.request_id, 42);
  EXPECT_EQ(r.failure, plan_result_t::NONE);
  EXPECT_EQ(r.planner, "CellBiRRT");
  EXPECT_EQ(r.trajectory.utime, 123456789);
  EXPECT_EQ(r.trajectory.num_joints, 7);
  EXPECT_EQ(static_cast<int>(r.trajectory.joint_names.size()), 7);
  EXPECT_EQ(r.trajectory.joint_names[0], "arm_1_joint");
  ASSERT_EQ(r.trajectory.num_points, static_cast<int>(r.trajectory.points.size()));
  ASSERT_GE(r.trajectory.num_points, 2);
  int64_t last = -1;
  for (const auto& p : r.trajectory.points) {
    EXPECT_EQ(p.num_joints, 7);
    EXPECT_EQ(p.positions.size(), 7u);
    EXPECT_EQ(p.velocities.size(), 7u);
    EXPECT_EQ(p.accelerations.size(), 7u);
    EXPECT_GT(p.utime, last);
    last = p.utime;
  }
  for (int j = 0; j < 7; ++j) {
    EXPECT_NEAR(r.trajectory.points.front().positions[j], kHome[j], 1e-9);
    EXPECT_NEAR(r.trajectory.points.back().positions[j], kUp[j], 1e-9);
  }
  EXPECT_GT(r.path_length_rad, 0.0);
  // Encodable: every length field matches its array.
  std::vector<uint8_t> buf(r.getEncodedSize());
  EXPECT_EQ(r.encode(buf.data(), 0, static_cast<int>(buf.size())), static_cast<int>(buf.size()));
}

TEST_F(PlannerNodeTest, BadRequestsAreAnsweredWithReasons) {
  plan_request_t r = joint_request(kHome, kUp);
  r.start_joints[3] = NAN;
  plan_result_t out = node_.process(r);
  EXPECT_FALSE(out.success);
  EXPECT_EQ(out.failure, plan_result_t::INVALID_REQUEST);
  EXPECT_NE(out.message.find("NaN"), std::string::npos) << out.message;

  r = joint_request({0, 0, 0, 0, 0, 0}, {0, 0, 0, 0, 0, 0});
  out = node_.process(r);
  EXPECT_EQ(out.failure, plan_result_t::INVALID_REQUEST);
  EXPECT_NE(out.message.find("num_joints"), std::string::npos) << out.message;
  EXPECT_EQ(out.trajectory.num_points, 0);

  r = joint_request(kHome, kUp);
  r.planner = "SuperPlanner";
  out = node_.process(r);
  EXPECT_EQ(out.failure, plan_result_t::UNKNOWN_PLANNER);
  EXPECT_NE(out.message.find("SuperPlanner"), std::string::npos);

  r = joint_request(kHome, kUp);
  r.goal_type = 7;
  EXPECT_EQ(node_.process(r).failure, plan_result_t::INVALID_REQUEST);

  r = joint_request(kHome, kUp);
  r.goal_type = plan_request_t::POSE;
  r.goal_pose.orientation[0] = 0.0;  // zero quaternion
  EXPECT_EQ(node_.process(r).failure, plan_result_t::INVALID_REQUEST);

  r = joint_request(kHome, kUp);
  r.time_budget_s = 1e6;
  EXPECT_EQ(node_.process(r).failure, plan_result_t::INVALID_REQUEST);

  r = joint_request(kHome, kUp);
  r.holding_book = true;
  r.held_book_size_m[1] = -0.2;
  EXPECT_EQ(node_.process(r).failure, plan_result_t::INVALID_REQUEST);

  r = joint_request(kHome, kUp);
  r.start_joints.pop_back();
  EXPECT_EQ(node_.process(r).failure, plan_result_t::INVALID_REQUEST);

  // then_poses: a count that differs from the list, a JOINTS goal with them, a NaN pose, another frame.
  r = joint_request(kHome, kUp);
  r.num_then_poses = 2;
  out = node_.process(r);
  EXPECT_EQ(out.failure, plan_result_t::INVALID_REQUEST);
  EXPECT_NE(out.message.find("num_then_poses"), std::string::npos) << out.message;
  r = joint_request(kHome, kUp);
  r.then_poses.push_back(isometry_to_pose(Eigen::Isometry3d::Identity(), "base", "gripper", 0));
  r.num_then_poses = 1;
  out = node_.process(r);
  EXPECT_EQ(out.failure, plan_result_t::INVALID_REQUEST);
  EXPECT_NE(out.message.find("POSE goal"), std::string::npos) << out.message;
  r.goal_type = plan_request_t::POSE;
  r.then_poses[0].position[1] = NAN;
  out = node_.process(r);
  EXPECT_EQ(out.failure, plan_result_t::INVALID_REQUEST);
  EXPECT_NE(out.message.find("then_poses[0]"), std::string::npos) << out.message;
  r.then_poses[0] = isometry_to_pose(Eigen::Isometry3d::Identity(), "cart", "gripper", 0);
  out = node_.process(r);
  EXPECT_EQ(out.failure, plan_result_t::INVALID_REQUEST);
  EXPECT_NE(out.message.find("'cart'"), std::string::npos) << out.message;
}

TEST_F(PlannerNodeTest, BadObstaclesAreAnsweredNamingTheBox) {
  const auto box = [](const std::string& name) {
    obstacle_box_t b;
    b.name = name;
    b.pose = isometry_to_pose(Eigen::Isometry3d::Identity(), "base", name, 0);
    b.size_m[0] = b.size_m[1] = b.size_m[2] = 0.05;
    return b;
  };
  plan_request_t r = joint_request(kHome, kUp);
  r.num_obstacles = 1;  // no box given
  plan_result_t out = node_.process(r);
  EXPECT_EQ(out.failure, plan_result_t::INVALID_REQUEST);
  EXPECT_NE(out.message.find("num_obstacles"), std::string::npos) << out.message;
  r.obstacles.push_back(box("book_0"));
  r.obstacles[0].pose.position[2] = NAN;
  out = node_.process(r);
  EXPECT_EQ(out.failure, plan_result_t::INVALID_REQUEST);
  EXPECT_NE(out.message.find("obstacles[0] ('book_0') pose"), std::string::npos) << out.message;
  r.obstacles[0] = box("book_0");
  r.obstacles[0].pose.frame = "cart";
  out = node_.process(r);
  EXPECT_EQ(out.failure, plan_result_t::INVALID_REQUEST);
  EXPECT_NE(out.message.find("'cart'"), std::string::npos) << out.message;
  for (const double bad : {0.0, -0.1, 5.0, double(NAN)}) {
    r.obstacles[0] = box("book_0");
    r.obstacles[0].size_m[1] = bad;
    out = node_.process(r);
    EXPECT_EQ(out.failure, plan_result_t::INVALID_REQUEST) << bad;
    EXPECT_NE(out.message.find("obstacles[0] ('book_0') size_m"), std::string::npos) << out.message;
  }
}

// A request's boxes are in the environment for that request: a goal inside one is refused naming it, a path past one
// goes around it (checked on the exact shapes at every trajectory sample), and the next request no longer has them.
TEST_F(PlannerNodeTest, RequestObstaclesAreAvoidedForThatRequestOnly) {
  const PlannerStack stack(node_.settings());
  const Eigen::Map<const Eigen::VectorXd> home(kHome.data(), 7), up(kUp.data(), 7);
  const auto obstacle_at = [](const Eigen::Vector3d& centre, double edge) {
    obstacle_box_t b;
    b.name = "placed_book_0";
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.translation() = centre;
    b.pose = isometry_to_pose(pose, "base", "placed_book_0", 0);
    b.size_m[0] = b.size_m[1] = b.size_m[2] = edge;
    return b;
  };
  // 1. A box around the goal's TCP: the goal is in collision with it.
  plan_request_t r = joint_request(kHome, kUp);
  r.obstacles.push_back(obstacle_at(stack.kinematics.tip_pose(up).translation(), 0.06));
  r.num_obstacles = 1;
  plan_result_t out = node_.process(r);
  EXPECT_FALSE(out.success);
  EXPECT_EQ(out.failure, plan_result_t::GOAL_IN_COLLISION) << out.message;
  EXPECT_NE(out.message.find("request_placed_book_0"), std::string::npos) << out.message;

  // 2. A box where the straight joint-space move passes the TCP halfway: the plan goes around it.
  const Eigen::VectorXd middle = 0.5 * (home + up);
  r.obstacles[0] = obstacle_at(stack.kinematics.tip_pose(middle).translation(), 0.10);
  PlanningScene with_box = stack.scene;
  std::vector<SceneBox> env = with_box.environment();
  const obstacle_box_t& b = r.obstacles[0];
  env.push_back(SceneBox{"box", pose_to_isometry(b.pose), Eigen::Vector3d(b.size_m[0], b.size_m[1], b.size_m[2])});
  with_box.set_environment(env);
  ASSERT_TRUE(with_box.is_valid(home));
  ASSERT_TRUE(with_box.is_valid(up));
  ASSERT_TRUE(with_box.check(middle, false).collision) << "the straight move must pass through the box";
  out = node_.process(r);
  ASSERT_TRUE(out.success) << out.message;
  for (const auto& p : out.trajectory.points) {
    const Eigen::Map<const Eigen::VectorXd> q(p.positions.data(), 7);
    const CollisionReport c = with_box.check(q, false);
    EXPECT_FALSE(c.collision) << c.describe() << " at t = " << p.utime * 1e-6 << " s";
  }

  // 3. The next request without boxes: the goal of 1. is free again.
  EXPECT_TRUE(node_.process(joint_request(kHome, kUp)).success);
}

TEST_F(PlannerNodeTest, CartMarkerMovesTheCartBoxes) {
  auto find = [&](const std::string& name) {
    for (const auto& b : node_.environment())
      if (b.name == name) return b;
    ADD_FAILURE() << "no box " << name;
    return SceneBox{};
  };
  // Nominal cart (config): upper shelf centre at cart (0.19, 0, -0.01), cart at (0.60, -0.05, 0).
  EXPECT_NEAR((find("cart_upper_shelf").pose.translation() - Eigen::Vector3d(0.79, -0.05, -0.01)).norm(), 0.0, 1e-6);
  // A cart 10 cm further away: the marker (on the rear board) moves by the same 10 cm.
  const Eigen::Isometry3d marker_nominal = node_.settings().geometry.marker_groups[0].role == "cart"
                                               ? node_.settings().geometry.marker_groups[0].nominal_object_in_base *
                                                     node_.settings().geometry.marker_groups[0].marker_in_object
                                               : node_.settings().geometry.marker_groups[1].nominal_object_in_base *
                                                     node_.settings().geometry.marker_groups[1].marker_in_object;
  Eigen::Isometry3d moved = marker_nominal;
  moved.translation().x() += 0.10;
  marker_detections_t m;
  m.utime = 5;
  m.num_markers = 1;
  marker_t tag;
  tag.utime = 5;
  tag.id = 0;
  tag.role = "cart";
  tag.pose_in_base = isometry_to_pose(moved, "base", "cart_marker", 5);
  tag.pose_in_camera = tag.pose_in_base;
  m.markers.push_back(tag);
  std::string reason;
  ASSERT_TRUE(node_.apply_markers(m, &reason)) << reason;
  EXPECT_NEAR((find("cart_upper_shelf").pose.translation() - Eigen::Vector3d(0.89, -0.05, -0.01)).norm(), 0.0, 1e-6);
  // A NaN pose is refused and changes nothing.
  m.markers[0].pose_in_base.position[0] = NAN;
  EXPECT_FALSE(node_.apply_markers(m, &reason));
  EXPECT_NE(reason.find("cart"), std::string::npos);
  EXPECT_NEAR(find("cart_upper_shelf").pose.translation().x(), 0.89, 1e-6);
}

/// Collects the PLAN_RESULT messages of a bus.
struct ResultSink {
  std::vector<plan_result_t> got;
  void on(const lcm::ReceiveBuffer*, const std::string&, const plan_result_t* msg) { got.push_back(*msg); }
};

TEST(PlannerNodeBus, AnswersOnTheBus) {
  Composition comp;
  PlannerSettings settings = PlannerSettings::load(kConfig);
  settings.defer_until_markers = false;  // plans at the nominal poses (the next test waits for MARKERS)
  auto& node = comp.add(std::make_unique<PlannerNode>(settings));
  (void)node;
  ResultSink sink;
  comp.bus().subscribe("PLAN_RESULT", &ResultSink::on, &sink);
  plan_request_t good = joint_request(kHome, kUp);
  comp.bus().publish("PLAN_REQUEST", &good);
  plan_request_t bad = joint_request(kHome, kUp);
  bad.request_id = 43;
  bad.planner = "nope";
  comp.bus().publish("PLAN_REQUEST", &bad);
  comp.spin();
  ASSERT_EQ(sink.got.size(), 2u);
  EXPECT_TRUE(sink.got[0].success) << sink.got[0].message;
  EXPECT_EQ(sink.got[1].request_id, 43);
  EXPECT_EQ(sink.got[1].failure, plan_result_t::UNKNOWN_PLANNER);
}

TEST(PlannerNodeBus, ARequestBeforeTheFirstMarkersIsAnsweredWhenTheyArrive) {
  // A planner restarted while the task runs: the coordinator's request comes before the first MARKERS.
  Composition comp;
  comp.add(std::make_unique<PlannerNode>(PlannerSettings::load(kConfig)));
  ResultSink sink;
  comp.bus().subscribe("PLAN_RESULT", &ResultSink::on, &sink);
  plan_request_t first = joint_request(kHome, kUp);
  first.request_id = 50;
  comp.bus().publish("PLAN_REQUEST", &first);
  plan_request_t second = joint_request(kHome, kUp);
  second.request_id = 51;
  comp.bus().publish("PLAN_REQUEST", &second);
  comp.spin();
  EXPECT_TRUE(sink.got.empty()) << "answered at the nominal cart pose";
  marker_detections_t m;
  m.utime = 7;
  m.num_markers = 0;  // a message without cart or holder changes nothing
  comp.bus().publish("MARKERS", &m);
  comp.spin();
  EXPECT_TRUE(sink.got.empty());
  const PlannerSettings settings = PlannerSettings::load(kConfig);
  const auto& g = settings.geometry.marker_groups[0];
  marker_t tag;
  tag.utime = 8;
  tag.role = g.role;
  tag.pose_in_base = isometry_to_pose(g.nominal_object_in_base * g.marker_in_object, "base", "marker", 8);
  tag.pose_in_camera = tag.pose_in_base;
  m.utime = 8;
  m.num_markers = 1;
  m.markers = {tag};
  comp.bus().publish("MARKERS", &m);
  comp.spin();
  ASSERT_EQ(sink.got.size(), 1u) << "the newest waiting request only";
  EXPECT_EQ(sink.got[0].request_id, 51);
  EXPECT_TRUE(sink.got[0].success) << sink.got[0].message;
}

}  // namespace
}  // namespace bookgrasp
