#pragma once
/// @file
/// Offscreen rendering of a MuJoCo camera: colour, exact metric depth and
/// per-pixel geom ids (segmentation), with the camera's pinhole calibration.

#include <memory>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <mujoco/mujoco.h>
#include <opencv2/core.hpp>

#include "common/sim_render/egl_context.h"
#include "common/sim_render/pinhole_camera.h"

namespace bookgrasp::sim_render {

/// How the renderer is set up once for a model.
struct RendererSettings {
  int max_width = 640;      ///< largest image width that will be requested (offscreen buffer)
  int max_height = 480;     ///< largest image height that will be requested
  int shadow_size = 1024;   ///< shadow map texture size (MuJoCo's default 4096 costs ~3x the time)
  bool shadows = true;      ///< draw shadows in colour images
  /// Body whose frame is `base` (camera poses are given in it); "" = MuJoCo's world frame.
  std::string base_body;
};

/// What to render from one camera.
struct RenderRequest {
  std::string camera;         ///< MJCF camera name, e.g. "stereo_left"
  int width = 640;            ///< pixels (<= RendererSettings::max_width)
  int height = 480;           ///< pixels (<= RendererSettings::max_height)
  bool rgb = true;            ///< colour image
  bool depth = false;         ///< metric depth
  bool segmentation = false;  ///< geom id per pixel
};

/// The images of one camera at one state. Rows are top row first (image
/// convention), pixels as PinholeCamera describes.
struct RenderedView {
  PinholeCamera camera;  ///< calibration and pose at the rendered state
  cv::Mat rgb;           ///< CV_8UC3, R,G,B order; empty unless requested
  cv::Mat depth;         ///< CV_32FC1, metres along the optical axis (z), NaN where nothing was hit; empty unless requested
  cv::Mat geom_id;       ///< CV_32SC1, MuJoCo geom id, -1 where no geom; empty unless requested
};

/// Renders cameras of one MuJoCo model into an offscreen buffer with its own
/// headless OpenGL context (EglContext). Not thread-safe; render from one
/// thread at a time (the context is made current on each call).
///
/// Depth is exact (within ~0.1 mm of mj_ray) because multisampling is off:
/// the constructor sets `m->vis.quality.offsamples = 0`, the shadow size and
/// the offscreen buffer size on the model before it makes the GPU context.
class OffscreenRenderer {
 public:
  /// Prepares rendering of `m` (which must outlive the renderer). Throws
  /// RenderError if no context can be made, std::invalid_argument for a
  /// bad setting (unknown base body, non-positive size).
  OffscreenRenderer(mjModel* m, const RendererSettings& settings);
  ~OffscreenRenderer();
  OffscreenRenderer(const OffscreenRenderer&) = delete;
  OffscreenRenderer& operator=(const OffscreenRenderer&) = delete;

  /// Renders `request` in the state `d` (kinematics must be current, e.g.
  /// after mj_forward). Throws std::invalid_argument for an unknown camera
  /// or a size beyond the settings.
  RenderedView render(mjData* d, const RenderRequest& request);

  /// The pinhole model of camera `camera` at state `d` for `width` x `height`
  /// images, without rendering. Throws std::invalid_argument for an unknown camera.
  PinholeCamera camera(const mjData* d, const std::string& camera, int width, int height) const;

  /// The `base` frame in MuJoCo's world frame at state `d`.
  Eigen::Isometry3d base_in_world(const mjData* d) const;

  /// The settings the renderer was made with.
  const RendererSettings& settings() const { return settings_; }

 private:
  int camera_id(const std::string& name) const;

  const mjModel* model_;
  RendererSettings settings_;
  int base_body_id_ = 0;
  std::unique_ptr<EglContext> gl_;
  mjvScene scene_;
  mjvOption option_;
  mjrContext context_;
  std::vector<unsigned char> rgb_buffer_;
  std::vector<float> depth_buffer_;
};

/// Maps a geom-id image (CV_32SC1, -1 = none) to owner labels with
/// `owner_of_geom[id]`; pixels without a geom get `none_label`.
cv::Mat map_geom_ids(const cv::Mat& geom_id, const std::vector<int>& owner_of_geom, int none_label);

}  // namespace bookgrasp::sim_render
