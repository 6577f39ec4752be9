// Scene geometry from configuration: boxes placed by marker poses, computed by hand.
#include "services/planner/scene_geometry.h"

#include <gtest/gtest.h>

namespace bookgrasp {
namespace {

const char* kYaml = R"(
scene:
  fixed_boxes:
    floor: {center: [0, 0, -0.6], rpy: [0, 0, 0], size: [4, 4, 0.1]}
  objects:
    cart:
      nominal_pose: {position: [0.6, 0.0, 0.0], rpy: [0, 0, 0]}
      marker_pose: {position: [0.3, 0.0, 0.2], rpy: [0, 0, 1.5707963267948966]}
      boxes:
        shelf: {center: [0.2, 0.0, -0.01], rpy: [0, 0, 0], size: [0.4, 0.8, 0.02]}
)";

TEST(SceneGeometry, NominalPoseUntilAMarkerIsSeen) {
  const Config root = Config::from_string(kYaml);
  const SceneGeometry g = scene_geometry_from_config(root.child("scene"));
  const auto boxes = build_environment(g, {});
  ASSERT_EQ(boxes.size(), 2u);
  EXPECT_EQ(boxes[0].name, "floor");
  EXPECT_EQ(boxes[1].name, "cart_shelf");
  EXPECT_TRUE(boxes[1].pose.translation().isApprox(Eigen::Vector3d(0.8, 0.0, -0.01)));
  EXPECT_TRUE(boxes[1].size.isApprox(Eigen::Vector3d(0.4, 0.8, 0.02)));
}

TEST(SceneGeometry, MarkerPoseMovesTheObject) {
  const Config root = Config::from_string(kYaml);
  const SceneGeometry g = scene_geometry_from_config(root.child("scene"));
  // The cart turned by 90 degrees about z and placed with its origin at (1, 0.5, 0):
  // marker = object * marker_in_object = (1, 0.5, 0) + Rz(90)(0.3, 0, 0.2) = (1, 0.8, 0.2), yaw 180.
  Eigen::Isometry3d marker = pose_from_rpy(Eigen::Vector3d(1.0, 0.8, 0.2), Eigen::Vector3d(0, 0, 3.14159265358979));
  const auto boxes = build_environment(g, {{"cart", marker}});
  // Shelf centre: (1, 0.5, 0) + Rz(90)(0.2, 0, -0.01) = (1, 0.7, -0.01); its x axis along base y.
  EXPECT_NEAR((boxes[1].pose.translation() - Eigen::Vector3d(1.0, 0.7, -0.01)).norm(), 0.0, 1e-9);
  EXPECT_NEAR((boxes[1].pose.linear().col(0) - Eigen::Vector3d(0, 1, 0)).norm(), 0.0, 1e-9);
  // Other roles do not move it.
  const auto same = build_environment(g, {{"holder", marker}});
  EXPECT_TRUE(same[1].pose.translation().isApprox(Eigen::Vector3d(0.8, 0.0, -0.01)));
}

TEST(SceneGeometry, RpyIsFixedAxesXyz) {
  // roll 90 about x: y -> z.
  const Eigen::Isometry3d t = pose_from_rpy(Eigen::Vector3d::Zero(), Eigen::Vector3d(1.5707963267948966, 0, 0));
  EXPECT_NEAR((t.linear() * Eigen::Vector3d::UnitY() - Eigen::Vector3d::UnitZ()).norm(), 0.0, 1e-12);
  // yaw after pitch: R = Rz Ry Rx.
  const Eigen::Isometry3d u = pose_from_rpy(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 1.5707963267948966, 1.5707963267948966));
  // Ry(90) x -> -z, then Rz(90) leaves -z.
  EXPECT_NEAR((u.linear() * Eigen::Vector3d::UnitX() - Eigen::Vector3d(0, 0, -1)).norm(), 0.0, 1e-12);
}

TEST(SceneGeometry, BadValuesNameTheKey) {
  const Config bad = Config::from_string(R"(
scene:
  fixed_boxes:
    floor: {center: [0, 0, -0.6], rpy: [0, 0, 0], size: [4, 0, 0.1]}
  objects: {}
)");
  try {
    scene_geometry_from_config(bad.child("scene"));
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.fixed_boxes.floor.size"), std::string::npos) << e.what();
  }
  const Config missing = Config::from_string("scene:\n  fixed_boxes: {}\n");
  EXPECT_THROW(scene_geometry_from_config(missing.child("scene")), ConfigError);
}

}  // namespace
}  // namespace bookgrasp
