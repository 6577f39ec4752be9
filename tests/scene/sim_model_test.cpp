// Tests of the MuJoCo model of a scene (common/scene/sim_model.h).
#include "common/scene/sim_model.h"

#include <cmath>

#include <gtest/gtest.h>

using namespace bookgrasp;
using namespace bookgrasp::scene;

namespace {
const std::string kScene = std::string(BOOKGRASP_SOURCE_DIR) + "/config/scenes/default.yaml";

Eigen::Matrix3d xmat(const mjtNum* m) {
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = m[3 * i + j];
  return r;
}
}  // namespace

TEST(SimModel, BuildsWithNamedCamerasJointsAndActuators) {
  const Scene s = load_scene(kScene, 1);
  SimModel sm = SimModel::build(s);
  const mjModel* m = sm.model();
  for (const char* cam : {"stereo_left", "stereo_right", "hand_camera"})
    EXPECT_GE(mj_name2id(m, mjOBJ_CAMERA, cam), 0) << cam;
  for (const auto& j : arm_joint_names()) EXPECT_GE(mj_name2id(m, mjOBJ_JOINT, j.c_str()), 0) << j;
  EXPECT_GE(mj_name2id(m, mjOBJ_ACTUATOR, "gripper"), 0);
  EXPECT_GE(mj_name2id(m, mjOBJ_SITE, "gripper"), 0);
  EXPECT_EQ(m->opt.cone, mjCONE_ELLIPTIC);
  EXPECT_GE(m->opt.impratio, 10.0);
  EXPECT_DOUBLE_EQ(m->opt.timestep, 0.002);
  EXPECT_GE(m->vis.global.offwidth, 640);
  EXPECT_GE(m->vis.global.offheight, 480);
  EXPECT_EQ(m->vis.quality.shadowsize, 1024);
  // URDF joint limits reach the model.
  const int j2 = mj_name2id(m, mjOBJ_JOINT, "arm_2_joint");
  EXPECT_NEAR(m->jnt_range[2 * j2], -1.97, 1e-9);
  EXPECT_NEAR(m->jnt_range[2 * j2 + 1], 1.97, 1e-9);
}

TEST(SimModel, GeomOwnersMapToBooksAndSceneParts) {
  const Scene s = load_scene(kScene, 1);
  SimModel sm = SimModel::build(s);
  const mjModel* m = sm.model();
  auto owner = [&](const char* name) { return sm.geom_owner_id(mj_name2id(m, mjOBJ_GEOM, name)); };
  EXPECT_EQ(owner("book_0"), 0);
  EXPECT_EQ(owner("book_0_pages"), 0);
  EXPECT_EQ(owner("book_3"), 3);
  EXPECT_EQ(owner("stripe"), kOwnerStripe);
  EXPECT_EQ(owner("cart_upper_shelf"), kOwnerCart);
  EXPECT_EQ(owner("cart_marker"), kOwnerCartMarker);
  EXPECT_EQ(owner("holder_marker"), kOwnerHolderMarker);
  EXPECT_EQ(owner("holder_back"), kOwnerHolder);
  EXPECT_EQ(owner("screen"), kOwnerScreen);
  EXPECT_EQ(owner("floor"), kOwnerFloor);
  EXPECT_EQ(owner("robot/gripper_finger_left"), kOwnerGripperFinger);
  EXPECT_EQ(owner("robot/arm_2_link"), kOwnerRobotArm);
  EXPECT_EQ(sm.geom_owner_id(-1), kOwnerNone);
  EXPECT_EQ(geom_owner_name(4), "book_4");
  EXPECT_EQ(geom_owner_name(kOwnerStripe), "stripe");
}

TEST(SimModel, CamerasMatchTheSceneAndTheUrdfOpticalFrame) {
  const Scene s = load_scene(kScene, 1);
  SimModel sm = SimModel::build(s);
  const mjModel* m = sm.model();
  const mjData* d = sm.data();
  const Eigen::Matrix3d flip = Eigen::Vector3d(1, -1, -1).asDiagonal();
  // Stereo: MuJoCo camera frame (x right, y up, -z forward) turned into the optical frame.
  const int left = mj_name2id(m, mjOBJ_CAMERA, "stereo_left");
  const Eigen::Matrix3d r_left = xmat(d->cam_xmat + 9 * left) * flip;
  EXPECT_TRUE(r_left.isApprox(s.stereo_left.pose.linear(), 1e-6));
  EXPECT_NEAR((Eigen::Vector3d(d->cam_xpos[3 * left], d->cam_xpos[3 * left + 1], d->cam_xpos[3 * left + 2]) -
               s.stereo_left.pose.translation()).norm(), 0.0, 1e-9);
  EXPECT_NEAR(m->cam_fovy[left], s.stereo_left.fovy_rad * 180 / M_PI, 1e-6);
  // Hand camera: optical frame = the URDF hand_camera link frame.
  const int hand = mj_name2id(m, mjOBJ_CAMERA, "hand_camera");
  const int body = mj_name2id(m, mjOBJ_BODY, "hand_camera");
  EXPECT_TRUE((xmat(d->cam_xmat + 9 * hand) * flip).isApprox(xmat(d->xmat + 9 * body), 1e-9));
  // The URDF says image x = gripper y and image z = gripper z (approach).
  const Eigen::Matrix3d g = xmat(d->xmat + 9 * mj_name2id(m, mjOBJ_BODY, "gripper"));
  const Eigen::Matrix3d c = xmat(d->cam_xmat + 9 * hand) * flip;
  EXPECT_NEAR(c.col(0).dot(g.col(1)), 1.0, 1e-9);
  EXPECT_NEAR(c.col(2).dot(g.col(2)), 1.0, 1e-9);
}

TEST(SimModel, BooksRestOnTheShelfAfterSettling) {
  for (uint64_t seed : {1, 2, 3}) {
    const Scene s = load_scene(kScene, seed);
    SimModel sm = SimModel::build(s);
    const ground_truth_t gt = sm.ground_truth(7);
    ASSERT_EQ(gt.num_books, static_cast<int>(s.books.size()));
    int rightmost = 0;
    for (const auto& b : gt.books) {
      EXPECT_EQ(b.place, "upper_shelf") << "seed " << seed << " " << b.name;
      rightmost += b.rightmost;
      // Settling: a leaning book (up to 3 deg) may tip onto its neighbour, its top moving up to h*sin(3 deg) ~ 1.6 cm.
      const Book& gen = s.books[b.id];
      const auto c = book_corners(gen.pose, gen.width_m, gen.height_m, gen.depth_m);
      EXPECT_LT((Eigen::Vector3d(b.p1_base[0], b.p1_base[1], b.p1_base[2]) - c[kP1CornerIndex]).norm(), 0.02)
          << "seed " << seed << " " << b.name;
      double zmin = 1e9;
      for (int i = 0; i < 8; ++i) zmin = std::min(zmin, b.corners_base[i][2]);
      EXPECT_NEAR(zmin, s.upper_shelf_z(), 0.002) << "seed " << seed << " " << b.name;
    }
    EXPECT_EQ(rightmost, 1);
    // The right-most book's P1 is its corner with the smallest y among the books' P1s.
    for (const auto& b : gt.books) {
      if (!b.rightmost) continue;
      for (const auto& o : gt.books) EXPECT_LE(b.p1_base[1], o.p1_base[1]);
      EXPECT_EQ(b.p1_base[0], b.corners_base[kP1CornerIndex][0]);
    }
    EXPECT_EQ(gt.utime, 7);
  }
}

TEST(SimModel, SameSeedGivesIdenticalStatesAfterSteps) {
  const Scene s = load_scene(kScene, 11);
  SimModel a = SimModel::build(s), b = SimModel::build(load_scene(kScene, 11));
  const std::vector<double> q = {0.2, 0.3, 0.0, 0.5, 0.0, 0.3, 0.1};
  a.set_arm_setpoint(q);
  b.set_arm_setpoint(q);
  a.step(300);
  b.step(300);
  const sim_state_t sa = a.state(1), sb = b.state(1);
  std::vector<uint8_t> ba(sa.getEncodedSize()), bb(sb.getEncodedSize());
  sa.encode(ba.data(), 0, ba.size());
  sb.encode(bb.data(), 0, bb.size());
  EXPECT_EQ(ba, bb);
  EXPECT_NEAR(a.arm_positions()[3], 0.5, 0.01);  // the position servo reached its setpoint
}

TEST(SimModel, ApplyRestoresAState) {
  const Scene s = load_scene(kScene, 4);
  SimModel a = SimModel::build(s);
  a.set_arm_setpoint({0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7});
  a.set_gripper_width(0.03);
  a.step(500);
  const sim_state_t st = a.state(5);
  SimModel b = SimModel::build(s);
  b.apply(st);
  const sim_state_t st2 = b.state(5);
  for (int i = 0; i < 7; ++i) EXPECT_DOUBLE_EQ(st.joint_positions[i], st2.joint_positions[i]);
  EXPECT_NEAR(st.gripper_width_m, st2.gripper_width_m, 1e-12);
  ASSERT_EQ(st.num_bodies, st2.num_bodies);
  for (int i = 0; i < st.num_bodies; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(st.bodies[i].position[j], st2.bodies[i].position[j], 1e-12);
  sim_state_t bad = st;
  bad.joint_positions[2] = std::nan("");
  EXPECT_THROW(b.apply(bad), std::invalid_argument);
}

TEST(SimModel, MoveBookPutsOneBookAtRestAndLeavesEverythingElse) {
  const Scene s = load_scene(kScene, 4);
  SimModel sm = SimModel::build(s);
  sm.step(10);
  const double t0 = sm.sim_time();
  const sim_state_t before = sm.state(0);
  const int id = s.books.front().id;
  sm.move_book(id, Eigen::Isometry3d(Eigen::Translation3d(-2.0, 1.0, s.floor_z + 0.2)));
  EXPECT_DOUBLE_EQ(sm.sim_time(), t0);
  sm.step(1000);  // 2 s: it falls 0.2 m minus half its size onto the floor and stays there
  const ground_truth_t g = sm.ground_truth(0);
  const sim_state_t after = sm.state(0);
  for (const auto& b : g.books) {
    if (b.id == id) {
      EXPECT_EQ(b.place, "other");
      EXPECT_NEAR(b.pose.position[0], -2.0, 0.05);
      EXPECT_NEAR(b.pose.position[1], 1.0, 0.05);
    } else {
      EXPECT_EQ(b.place, "upper_shelf") << "book " << b.id;
    }
  }
  for (int i = 0; i < 7; ++i) EXPECT_NEAR(after.joint_positions[i], before.joint_positions[i], 1e-3);
  EXPECT_THROW(sm.move_book(9999, Eigen::Isometry3d::Identity()), std::invalid_argument);
  Eigen::Isometry3d nan_pose = Eigen::Isometry3d::Identity();
  nan_pose.translation().x() = std::nan("");
  EXPECT_THROW(sm.move_book(id, nan_pose), std::invalid_argument);
}

TEST(SimModel, RejectsBadArmSetpoints) {
  SimModel sm = SimModel::build(load_scene(kScene, 1));
  EXPECT_THROW(sm.set_arm_setpoint({0, 0, 0}), std::invalid_argument);
  EXPECT_THROW(sm.set_arm_setpoint({0, 0, 0, 0, 0, 0, std::nan("")}), std::invalid_argument);
  EXPECT_THROW(sm.set_arm_setpoint({0, 2.5, 0, 0, 0, 0, 0}), std::invalid_argument);
  EXPECT_THROW(sm.set_gripper_width(std::nan("")), std::invalid_argument);
}
