#include "common/sim_render/offscreen_renderer.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <opencv2/core.hpp>

namespace bookgrasp::sim_render {

OffscreenRenderer::OffscreenRenderer(mjModel* m, const RendererSettings& settings)
    : model_(m), settings_(settings) {
  if (!m) throw std::invalid_argument("OffscreenRenderer: model is null");
  if (settings.max_width <= 0 || settings.max_height <= 0) {
    throw std::invalid_argument("OffscreenRenderer: max_width and max_height must be positive");
  }
  if (settings.shadow_size < 64) throw std::invalid_argument("OffscreenRenderer: shadow_size must be >= 64");
  if (!settings.base_body.empty()) {
    base_body_id_ = mj_name2id(m, mjOBJ_BODY, settings.base_body.c_str());
    if (base_body_id_ < 0) {
      throw std::invalid_argument("OffscreenRenderer: the model has no body named '" + settings.base_body +
                                  "' (base_body); give an existing body or \"\" for the world frame");
    }
  }
  m->vis.global.offwidth = settings.max_width;
  m->vis.global.offheight = settings.max_height;
  m->vis.quality.offsamples = 0;  // exact depth, crisp segmentation
  m->vis.quality.shadowsize = settings.shadow_size;

  gl_ = std::make_unique<EglContext>();
  mjv_defaultScene(&scene_);
  mjv_defaultOption(&option_);
  mjr_defaultContext(&context_);
  mjv_makeScene(m, &scene_, 2000 + 4 * m->ngeom);
  mjr_makeContext(m, &context_, mjFONTSCALE_100);
  mjr_setBuffer(mjFB_OFFSCREEN, &context_);
  if (context_.currentBuffer != mjFB_OFFSCREEN) {
    mjr_freeContext(&context_);
    mjv_freeScene(&scene_);
    throw RenderError("MuJoCo offscreen framebuffer unavailable in the EGL context");
  }
  rgb_buffer_.resize(3 * static_cast<size_t>(settings.max_width) * settings.max_height);
  depth_buffer_.resize(static_cast<size_t>(settings.max_width) * settings.max_height);
}

OffscreenRenderer::~OffscreenRenderer() {
  try {
    gl_->make_current();
  } catch (...) {
  }
  mjr_freeContext(&context_);
  mjv_freeScene(&scene_);
}

int OffscreenRenderer::camera_id(const std::string& name) const {
  const int id = mj_name2id(model_, mjOBJ_CAMERA, name.c_str());
  if (id < 0) throw std::invalid_argument("the model has no camera named '" + name + "'");
  return id;
}

Eigen::Isometry3d OffscreenRenderer::base_in_world(const mjData* d) const {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  const int b = base_body_id_;
  Eigen::Matrix3d r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = d->xmat[9 * b + 3 * i + j];
  t.linear() = r;
  t.translation() = Eigen::Vector3d(d->xpos[3 * b], d->xpos[3 * b + 1], d->xpos[3 * b + 2]);
  return t;
}

PinholeCamera OffscreenRenderer::camera(const mjData* d, const std::string& name, int width, int height) const {
  return pinhole_from_model(model_, d, camera_id(name), width, height, base_in_world(d));
}

RenderedView OffscreenRenderer::render(mjData* d, const RenderRequest& request) {
  if (request.width <= 0 || request.height <= 0 || request.width > settings_.max_width ||
      request.height > settings_.max_height) {
    throw std::invalid_argument("render size " + std::to_string(request.width) + "x" +
                                std::to_string(request.height) + " outside 1x1.." +
                                std::to_string(settings_.max_width) + "x" + std::to_string(settings_.max_height) +
                                " (raise the renderer's max_width/max_height)");
  }
  const int cam_id = camera_id(request.camera);
  gl_->make_current();

  RenderedView view;
  view.camera = pinhole_from_model(model_, d, cam_id, request.width, request.height, base_in_world(d));
  const int w = request.width, h = request.height;
  const mjrRect viewport = {0, 0, w, h};

  mjvCamera cam;
  mjv_defaultCamera(&cam);
  cam.type = mjCAMERA_FIXED;
  cam.fixedcamid = cam_id;
  mjv_updateScene(model_, d, &option_, nullptr, &cam, mjCAT_ALL, &scene_);

  if (request.rgb || request.depth) {
    scene_.flags[mjRND_SEGMENT] = 0;
    scene_.flags[mjRND_IDCOLOR] = 0;
    scene_.flags[mjRND_SHADOW] = settings_.shadows && request.rgb ? 1 : 0;
    mjr_render(viewport, &scene_, &context_);
    mjr_readPixels(request.rgb ? rgb_buffer_.data() : nullptr, request.depth ? depth_buffer_.data() : nullptr,
                   viewport, &context_);
    if (request.rgb) {
      cv::Mat bottom_up(h, w, CV_8UC3, rgb_buffer_.data());
      cv::flip(bottom_up, view.rgb, 0);
    }
    if (request.depth) {
      const double extent = model_->stat.extent;
      const double n = model_->vis.map.znear * extent;
      const double f = model_->vis.map.zfar * extent;
      view.depth.create(h, w, CV_32FC1);
      const float nan = std::numeric_limits<float>::quiet_NaN();
      for (int r = 0; r < h; ++r) {
        const float* src = depth_buffer_.data() + static_cast<size_t>(h - 1 - r) * w;
        float* dst = view.depth.ptr<float>(r);
        for (int c = 0; c < w; ++c) {
          const double z = src[c];
          dst[c] = z >= 1.0 ? nan : static_cast<float>(n * f / (f - z * (f - n)));
        }
      }
    }
  }
  if (request.segmentation) {
    const mjtByte saved_skybox = scene_.flags[mjRND_SKYBOX];
    scene_.flags[mjRND_SEGMENT] = 1;
    scene_.flags[mjRND_IDCOLOR] = 1;
    scene_.flags[mjRND_SHADOW] = 0;
    scene_.flags[mjRND_SKYBOX] = 0;
    mjr_render(viewport, &scene_, &context_);
    mjr_readPixels(rgb_buffer_.data(), nullptr, viewport, &context_);
    scene_.flags[mjRND_SEGMENT] = 0;
    scene_.flags[mjRND_IDCOLOR] = 0;
    scene_.flags[mjRND_SKYBOX] = saved_skybox;
    view.geom_id.create(h, w, CV_32SC1);
    for (int r = 0; r < h; ++r) {
      const unsigned char* src = rgb_buffer_.data() + 3 * static_cast<size_t>(h - 1 - r) * w;
      int* dst = view.geom_id.ptr<int>(r);
      for (int c = 0; c < w; ++c) {
        const int segid = (src[3 * c] | (src[3 * c + 1] << 8) | (src[3 * c + 2] << 16)) - 1;
        int geom = -1;
        if (segid >= 0 && segid < scene_.ngeom && scene_.geoms[segid].objtype == mjOBJ_GEOM) {
          geom = scene_.geoms[segid].objid;
        }
        dst[c] = geom;
      }
    }
  }
  return view;
}

cv::Mat map_geom_ids(const cv::Mat& geom_id, const std::vector<int>& owner_of_geom, int none_label) {
  CV_Assert(geom_id.type() == CV_32SC1);
  cv::Mat out(geom_id.size(), CV_32SC1);
  for (int r = 0; r < geom_id.rows; ++r) {
    const int* src = geom_id.ptr<int>(r);
    int* dst = out.ptr<int>(r);
    for (int c = 0; c < geom_id.cols; ++c) {
      const int g = src[c];
      dst[c] = (g >= 0 && g < static_cast<int>(owner_of_geom.size())) ? owner_of_geom[g] : none_label;
    }
  }
  return out;
}

}  // namespace bookgrasp::sim_render
