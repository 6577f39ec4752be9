// hand_camera: files backend on the Middlebury images; sim backend stamps and
// camera pose at capture from the state; bad input.
#include "services/hand_camera/hand_camera_node.h"

#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/composition.h"
#include "common/image_conversion.h"
#include "common/pose_conversion.h"
#include "common/scene/scene.h"
#include "common/scene/sim_model.h"

namespace bookgrasp {
namespace {

const std::string kSource = BOOKGRASP_SOURCE_DIR;

HandCameraSettings default_settings(const std::string& backend) {
  HandCameraSettings s =
      HandCameraSettings::from_config(Config::load_file(kSource + "/config/services/hand_camera.yaml"));
  s.backend = backend;
  return s;
}

TEST(HandCameraFiles, PublishesTheFolderImagesWithTheFileCalibration) {
  HandCameraSettings s = default_settings("files");
  HandCameraNode node(s);
  ASSERT_EQ(node.num_images(), 1u);
  hand_image_t m;
  ASSERT_TRUE(node.next_file_frame(&m));
  EXPECT_EQ(m.utime, s.start_utime);
  EXPECT_EQ(m.calibration.frame, "hand_camera");
  EXPECT_EQ(m.calibration.camera_in_base.frame, "base");
  EXPECT_EQ(m.calibration.width, 450);
  cv::Mat bgr = cv::imread(kSource + "/tests/data/middlebury/Teddy/im2.png"), rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  EXPECT_EQ(cv::norm(image_to_mat(m.image), rgb, cv::NORM_INF), 0.0);
  ASSERT_TRUE(node.next_file_frame(&m));  // loop
  EXPECT_EQ(m.utime, s.start_utime + 500000);
  EXPECT_EQ(m.sequence, 1);
}

struct Collector {
  std::vector<hand_image_t> got;
  void on(const lcm::ReceiveBuffer*, const std::string&, const hand_image_t* m) { got.push_back(*m); }
};

/// Pose of the hand_camera optical frame computed from the simulation's own model (site/camera
/// positions are MuJoCo's forward kinematics of the state's joints).
Eigen::Isometry3d true_hand_camera_pose(scene::SimModel& sim) {
  const mjModel* m = sim.model();
  const mjData* d = sim.data();
  const int id = mj_name2id(m, mjOBJ_CAMERA, "hand_camera");
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d r;
  for (int i = 0; i < 9; ++i) r(i / 3, i % 3) = d->cam_xmat[9 * id + i];
  t.linear() = r * Eigen::Vector3d(1, -1, -1).asDiagonal();  // MuJoCo camera (-z view, y up) -> optical
  t.translation() = Eigen::Vector3d(d->cam_xpos[3 * id], d->cam_xpos[3 * id + 1], d->cam_xpos[3 * id + 2]);
  return t;
}

TEST(HandCameraSim, PoseAtCaptureFollowsTheStateAndBadStatesAreRejected) {
  HandCameraSettings s = default_settings("sim");
  s.seed = 1;
  scene::SimModel sim = scene::SimModel::build(scene::load_scene(s.scene_file, 1));
  Composition comp;
  HandCameraNode& node = comp.add(std::make_unique<HandCameraNode>(s));
  Collector col;
  comp.bus().subscribe("HAND_IMAGE", &Collector::on, &col);
  std::vector<double> q = sim.arm_positions();
  std::vector<Eigen::Isometry3d> truth;
  for (int k = 0; k < 3; ++k) {
    q[0] += 0.1;
    q[3] += 0.05;
    sim_state_t st = sim.state(k * 100000);
    for (int i = 0; i < st.num_joints; ++i)
      for (int j = 0; j < 7; ++j)
        if (st.joint_names[i] == scene::arm_joint_names()[j]) st.joint_positions[i] = q[j];
    sim.apply(st);
    truth.push_back(true_hand_camera_pose(sim));
    comp.bus().publish("SIM_STATE", &st);
    comp.spin();
  }
  ASSERT_EQ(col.got.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    const hand_image_t& m = col.got[k];
    EXPECT_EQ(m.utime, k * 100000);
    EXPECT_EQ(m.calibration.utime, m.utime);
    EXPECT_EQ(m.calibration.frame, "hand_camera");
    const Eigen::Isometry3d pose = pose_to_isometry(m.calibration.camera_in_base);
    EXPECT_LT((pose.translation() - truth[k].translation()).norm(), 1e-9);
    EXPECT_TRUE(pose.linear().isApprox(truth[k].linear(), 1e-9));
    EXPECT_EQ(image_to_mat(m.image).cols, 640);
  }
  // Successive poses differ (the arm moved).
  EXPECT_GT((pose_to_isometry(col.got[0].calibration.camera_in_base).translation() -
             pose_to_isometry(col.got[2].calibration.camera_in_base).translation())
                .norm(),
            0.01);
  sim_state_t bad = sim.state(400000);
  bad.num_joints -= 1;  // wrong joint count: the last joint is left out
  bad.joint_names.pop_back();
  bad.joint_positions.pop_back();
  bad.joint_velocities.pop_back();
  comp.bus().publish("SIM_STATE", &bad);
  comp.spin();
  EXPECT_EQ(node.rejected_total(), 1);
  EXPECT_NE(node.last_error().find("missing"), std::string::npos) << node.last_error();
  EXPECT_EQ(col.got.size(), 3u);
}

TEST(HandCameraSim, ABacklogOfStatesIsSkippedAndOnlyTheNewestDueOneRendered) {
  // A camera slower than the simulation: three due states (0.1 s apart) wait when it gets to them. It renders
  // the newest once they are dispatched, not each in turn (images 2-3 s late in the deployed kill test).
  HandCameraSettings s = default_settings("sim");
  s.seed = 1;
  scene::SimModel sim = scene::SimModel::build(scene::load_scene(s.scene_file, 1));
  Composition comp;
  comp.add(std::make_unique<HandCameraNode>(s));
  Collector col;
  comp.bus().subscribe("HAND_IMAGE", &Collector::on, &col);
  for (int k = 0; k < 3; ++k) {
    const sim_state_t st = sim.state(k * 100000);
    comp.bus().publish("SIM_STATE", &st);
  }
  comp.spin();
  ASSERT_EQ(col.got.size(), 1u);
  EXPECT_EQ(col.got[0].utime, 200000);
  // The next due state, alone, is rendered as before.
  const sim_state_t next = sim.state(300000);
  comp.bus().publish("SIM_STATE", &next);
  comp.spin();
  ASSERT_EQ(col.got.size(), 2u);
  EXPECT_EQ(col.got[1].utime, 300000);
}

}  // namespace
}  // namespace bookgrasp
