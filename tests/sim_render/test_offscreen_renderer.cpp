// Renderer against MuJoCo's own ray caster (mj_ray) and the model geometry:
// depth, segmentation, calibration and determinism.
#include "common/sim_render/offscreen_renderer.h"

#include <cmath>
#include <memory>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

namespace bookgrasp::sim_render {
namespace {

const char* kScene = BOOKGRASP_SOURCE_DIR "/tests/sim_render/data/camera_test_scene.xml";

class RendererTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char error[1000] = "";
    model_ = mj_loadXML(kScene, nullptr, error, sizeof(error));
    ASSERT_NE(model_, nullptr) << error;
    data_ = mj_makeData(model_);
    mj_forward(model_, data_);
    RendererSettings settings;
    settings.base_body = "base";
    renderer_ = std::make_unique<OffscreenRenderer>(model_, settings);
  }
  void TearDown() override {
    renderer_.reset();
    if (data_) mj_deleteData(data_);
    if (model_) mj_deleteModel(model_);
  }

  /// Corners of box geom `name` in base.
  std::vector<Eigen::Vector3d> box_corners_base(const std::string& name) const {
    const int g = mj_name2id(model_, mjOBJ_GEOM, name.c_str());
    Eigen::Matrix3d r;
    for (int i = 0; i < 9; ++i) r(i / 3, i % 3) = data_->geom_xmat[9 * g + i];
    const Eigen::Vector3d p(data_->geom_xpos[3 * g], data_->geom_xpos[3 * g + 1], data_->geom_xpos[3 * g + 2]);
    const Eigen::Vector3d s(model_->geom_size[3 * g], model_->geom_size[3 * g + 1], model_->geom_size[3 * g + 2]);
    const Eigen::Isometry3d world_to_base = renderer_->base_in_world(data_).inverse();
    std::vector<Eigen::Vector3d> out;
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3d local((k & 1 ? 1 : -1) * s.x(), (k & 2 ? 1 : -1) * s.y(), (k & 4 ? 1 : -1) * s.z());
      out.push_back(world_to_base * (p + r * local));
    }
    return out;
  }

  mjModel* model_ = nullptr;
  mjData* data_ = nullptr;
  std::unique_ptr<OffscreenRenderer> renderer_;
};

/// True if a geom-id change lies within one pixel of (r, c).
bool near_edge(const cv::Mat& ids, int r, int c) {
  const int v = ids.at<int>(r, c);
  for (int dr = -1; dr <= 1; ++dr)
    for (int dc = -1; dc <= 1; ++dc) {
      const int rr = r + dr, cc = c + dc;
      if (rr < 0 || cc < 0 || rr >= ids.rows || cc >= ids.cols) return true;
      if (ids.at<int>(rr, cc) != v) return true;
    }
  return false;
}

TEST_F(RendererTest, DepthAndSegmentationMatchRayCasting) {
  for (const char* camera : {"stereo_left", "stereo_right", "hand_camera"}) {
    RenderRequest req;
    req.camera = camera;
    req.depth = true;
    req.segmentation = true;
    const RenderedView view = renderer_->render(data_, req);
    ASSERT_EQ(view.rgb.type(), CV_8UC3);
    ASSERT_EQ(view.depth.type(), CV_32FC1);
    ASSERT_EQ(view.geom_id.type(), CV_32SC1);
    const Eigen::Isometry3d cam_in_world = renderer_->base_in_world(data_) * view.camera.camera_in_base;
    int compared = 0, hits_with_geom = 0;
    double worst = 0.0;
    for (int r = 0; r < view.depth.rows; r += 6) {
      for (int c = 0; c < view.depth.cols; c += 6) {
        if (near_edge(view.geom_id, r, c)) continue;
        const Eigen::Vector3d ray_cam = view.camera.ray(c, r);
        const Eigen::Vector3d dir = (cam_in_world.linear() * ray_cam).normalized();
        const Eigen::Vector3d origin = cam_in_world.translation();
        int geom = -1;
        const double dist = mj_ray(model_, data_, origin.data(), dir.data(), nullptr, 1, -1, &geom);
        if (geom < 0) {
          EXPECT_TRUE(std::isnan(view.depth.at<float>(r, c))) << camera << " pixel " << c << "," << r;
          continue;
        }
        const double z_true = dist / ray_cam.norm();
        const double err = std::abs(view.depth.at<float>(r, c) - z_true);
        worst = std::max(worst, err);
        EXPECT_LT(err, 1e-4) << camera << " pixel " << c << "," << r << " z " << z_true;
        EXPECT_EQ(view.geom_id.at<int>(r, c), geom) << camera << " pixel " << c << "," << r;
        ++compared;
        if (geom != 0) ++hits_with_geom;
      }
    }
    EXPECT_GT(compared, 3000) << camera;
    EXPECT_GT(hits_with_geom, 50) << camera << ": the boxes should be in view";
    RecordProperty(std::string("worst_depth_error_m_") + camera, std::to_string(worst));
  }
}

/// Signed distance of pixel centre `p` to the convex polygon `hull` (> 0 inside).
double signed_distance(const std::vector<cv::Point2f>& hull, const cv::Point2f& p) {
  return cv::pointPolygonTest(hull, p, true);
}

TEST_F(RendererTest, ProjectedCornersMatchRenderedSilhouetteWithinOnePixel) {
  for (const char* camera : {"stereo_left", "stereo_right", "hand_camera"}) {
    RenderRequest req;
    req.camera = camera;
    req.rgb = false;
    req.segmentation = true;
    const RenderedView view = renderer_->render(data_, req);
    for (const char* box : {"book_box", "crate_box"}) {
      const int g = mj_name2id(model_, mjOBJ_GEOM, box);
      std::vector<cv::Point2f> pts;
      for (const auto& corner : box_corners_base(box)) {
        const Eigen::Vector2d uv = view.camera.project(corner);
        pts.emplace_back(static_cast<float>(uv.x()), static_cast<float>(uv.y()));
      }
      std::vector<cv::Point2f> hull;
      cv::convexHull(pts, hull);
      int checked_vertices = 0;
      for (const auto& vertex : hull) {
        if (vertex.x < 5 || vertex.y < 5 || vertex.x > view.camera.width - 6 || vertex.y > view.camera.height - 6)
          continue;
        // Around each silhouette corner: pixels more than 1 px inside must be
        // the box, pixels more than 1 px outside must not.
        int inside = 0, outside = 0;
        for (int r = static_cast<int>(vertex.y) - 4; r <= static_cast<int>(vertex.y) + 4; ++r) {
          for (int c = static_cast<int>(vertex.x) - 4; c <= static_cast<int>(vertex.x) + 4; ++c) {
            const double s = signed_distance(hull, cv::Point2f(static_cast<float>(c), static_cast<float>(r)));
            const bool is_box = view.geom_id.at<int>(r, c) == g;
            if (s > 1.0) {
              EXPECT_TRUE(is_box) << camera << " " << box << " pixel " << c << "," << r;
              ++inside;
            } else if (s < -1.0) {
              EXPECT_FALSE(is_box) << camera << " " << box << " pixel " << c << "," << r;
              ++outside;
            }
          }
        }
        if (inside > 0 && outside > 0) ++checked_vertices;
      }
      EXPECT_GE(checked_vertices, 4) << camera << " " << box;
    }
  }
}

TEST_F(RendererTest, CalibrationFollowsTheMovingHandCamera) {
  const PinholeCamera before = renderer_->camera(data_, "hand_camera", 640, 480);
  data_->qpos[model_->jnt_qposadr[mj_name2id(model_, mjOBJ_JOINT, "slide")]] = 0.1;
  mj_forward(model_, data_);
  RenderRequest req;
  req.camera = "hand_camera";
  const RenderedView view = renderer_->render(data_, req);
  // The slide moves the gripper 0.1 m along world x; base is rotated 10 deg about z.
  const Eigen::Vector3d moved = view.camera.camera_in_base.translation() - before.camera_in_base.translation();
  const double yaw = 10.0 * M_PI / 180.0;
  EXPECT_NEAR(moved.x(), 0.1 * std::cos(yaw), 1e-9);
  EXPECT_NEAR(moved.y(), -0.1 * std::sin(yaw), 1e-9);
  EXPECT_NEAR(moved.z(), 0.0, 1e-9);
  EXPECT_TRUE(view.camera.camera_in_base.linear().isApprox(before.camera_in_base.linear(), 1e-12));
  // fovy 60 at 480 rows: fx = 240 / tan(30 deg).
  EXPECT_NEAR(view.camera.fx, 240.0 / std::tan(M_PI / 6.0), 1e-9);
  EXPECT_DOUBLE_EQ(view.camera.cx, 319.5);
  EXPECT_DOUBLE_EQ(view.camera.cy, 239.5);
}

TEST_F(RendererTest, SameStateGivesIdenticalPixels) {
  RenderRequest req;
  req.camera = "stereo_left";
  req.depth = true;
  req.segmentation = true;
  const RenderedView a = renderer_->render(data_, req);
  req.camera = "hand_camera";
  renderer_->render(data_, req);  // something else in between
  req.camera = "stereo_left";
  const RenderedView b = renderer_->render(data_, req);
  EXPECT_EQ(cv::norm(a.rgb, b.rgb, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::countNonZero(a.geom_id != b.geom_id), 0);
  EXPECT_EQ(std::memcmp(a.depth.data, b.depth.data, a.depth.total() * sizeof(float)), 0);
  // The colour image shows something: the mean is neither black nor saturated.
  const cv::Scalar mean = cv::mean(a.rgb);
  EXPECT_GT(mean[0], 20.0);
  EXPECT_LT(mean[0], 240.0);
}

TEST_F(RendererTest, SmallerImagesKeepTheFieldOfView) {
  RenderRequest req;
  req.camera = "stereo_left";
  req.width = 320;
  req.height = 240;
  req.segmentation = true;
  const RenderedView view = renderer_->render(data_, req);
  EXPECT_EQ(view.rgb.cols, 320);
  EXPECT_EQ(view.rgb.rows, 240);
  EXPECT_NEAR(view.camera.fx, 120.0 / std::tan(25.0 * M_PI / 180.0), 1e-9);
  const int g = mj_name2id(model_, mjOBJ_GEOM, "book_box");
  const Eigen::Vector3d centre(data_->geom_xpos[3 * g], data_->geom_xpos[3 * g + 1], data_->geom_xpos[3 * g + 2]);
  const Eigen::Vector2d uv = view.camera.project(renderer_->base_in_world(data_).inverse() * centre);
  EXPECT_EQ(view.geom_id.at<int>(static_cast<int>(std::lround(uv.y())), static_cast<int>(std::lround(uv.x()))), g);
}

TEST_F(RendererTest, BadRequestsAreRefusedWithAReason) {
  RenderRequest req;
  req.camera = "no_such_camera";
  try {
    renderer_->render(data_, req);
    FAIL() << "unknown camera accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_camera"), std::string::npos);
  }
  req.camera = "stereo_left";
  req.width = 1280;
  EXPECT_THROW(renderer_->render(data_, req), std::invalid_argument);
  req.width = 0;
  EXPECT_THROW(renderer_->render(data_, req), std::invalid_argument);
  RendererSettings bad;
  bad.base_body = "no_such_body";
  EXPECT_THROW(OffscreenRenderer(model_, bad), std::invalid_argument);
}

TEST_F(RendererTest, MapsGeomIdsToOwners) {
  cv::Mat ids = (cv::Mat_<int>(1, 4) << -1, 0, 2, 7);
  const cv::Mat owners = map_geom_ids(ids, {10, 11, 12}, -5);
  EXPECT_EQ(owners.at<int>(0, 0), -5);
  EXPECT_EQ(owners.at<int>(0, 1), 10);
  EXPECT_EQ(owners.at<int>(0, 2), 12);
  EXPECT_EQ(owners.at<int>(0, 3), -5);
}

}  // namespace
}  // namespace bookgrasp::sim_render
