#include "synthetic_shelf.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace bookgrasp::bws::test {

namespace {

uint32_t hash3(uint32_t a, uint32_t b, uint32_t c) {
  uint32_t h = a * 0x9E3779B1u ^ (b + 0x7F4A7C15u) * 0x85EBCA77u ^ (c + 0x165667B1u) * 0xC2B2AE3Du;
  h ^= h >> 15;
  h *= 0x2C1B3C6Du;
  h ^= h >> 12;
  h *= 0x297A2D39u;
  h ^= h >> 15;
  return h;
}

/// Value noise in [0, 1] on a lattice of `cell` metres.
float value_noise(double u, double v, double cell, uint32_t seed) {
  const double fu = u / cell, fv = v / cell;
  const double iu = std::floor(fu), iv = std::floor(fv);
  const double tu = fu - iu, tv = fv - iv;
  auto at = [&](int du, int dv) {
    return float(hash3(uint32_t(int64_t(iu) + du), uint32_t(int64_t(iv) + dv), seed) & 0xffff) / 65535.f;
  };
  const float a = at(0, 0), b = at(1, 0), c = at(0, 1), d = at(1, 1);
  return float((a * (1 - tu) + b * tu) * (1 - tv) + (c * (1 - tu) + d * tu) * tv);
}

struct Hit {
  double t = std::numeric_limits<double>::infinity();
  int box = -1;
  int face = -1;
  Eigen::Vector3d local;
};

void intersect(const std::vector<Box>& boxes, const std::vector<Eigen::Isometry3d>& inv, const Eigen::Vector3d& o,
               const Eigen::Vector3d& d, Hit& hit) {
  for (size_t i = 0; i < boxes.size(); ++i) {
    const Eigen::Vector3d lo = inv[i] * o;
    const Eigen::Vector3d ld = inv[i].linear() * d;
    double t0 = -std::numeric_limits<double>::infinity(), t1 = std::numeric_limits<double>::infinity();
    int face = -1;
    bool miss = false;
    for (int a = 0; a < 3; ++a) {
      const double h = boxes[i].half(a);
      if (std::fabs(ld(a)) < 1e-15) {
        if (std::fabs(lo(a)) > h) {
          miss = true;
          break;
        }
        continue;
      }
      double ta = (-h - lo(a)) / ld(a), tb = (h - lo(a)) / ld(a);
      int fa = 2 * a, fb = 2 * a + 1;  // entering through -h face when ld > 0
      if (ta > tb) {
        std::swap(ta, tb);
        std::swap(fa, fb);
      }
      if (ta > t0) {
        t0 = ta;
        face = fa;
      }
      t1 = std::min(t1, tb);
    }
    if (miss || t0 > t1 || t0 <= 1e-9 || face < 0) continue;
    if (t0 < hit.t) {
      hit.t = t0;
      hit.box = int(i);
      hit.face = face;
      hit.local = lo + t0 * ld;
    }
  }
}

Eigen::Isometry3d make_iso(const Eigen::Vector3d& t, const Eigen::Matrix3d& R) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = t;
  return T;
}

Eigen::Isometry3d shift(const Eigen::Isometry3d& frame, const Eigen::Vector3d& local) {
  return frame * make_iso(local, Eigen::Matrix3d::Identity());
}

}  // namespace

RenderOutput render_boxes(const std::vector<Box>& boxes, const PinholeCamera& cam, bool intensity, int ss) {
  std::vector<Eigen::Isometry3d> inv;
  for (const Box& b : boxes) inv.push_back(b.pose.inverse());
  RenderOutput out;
  out.depth = cv::Mat(cam.height, cam.width, CV_32F, cv::Scalar(std::numeric_limits<float>::quiet_NaN()));
  out.face_id = cv::Mat(cam.height, cam.width, CV_32S, cv::Scalar(0));
  if (intensity) out.intensity = cv::Mat(cam.height, cam.width, CV_8U, cv::Scalar(0));
  const Eigen::Vector3d o = cam.in_base.translation();
  const Eigen::Matrix3d R = cam.in_base.linear();
  const Eigen::Vector3d light = Eigen::Vector3d(-0.4, 0.3, 1.0).normalized();
  for (int v = 0; v < cam.height; ++v) {
    for (int u = 0; u < cam.width; ++u) {
      const Eigen::Vector3d rc((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
      Hit hit;
      intersect(boxes, inv, o, R * rc, hit);
      if (hit.box >= 0) {
        out.depth.at<float>(v, u) = float(hit.t);  // rc has z = 1, so t is the z depth
        out.face_id.at<int>(v, u) = hit.box * 6 + hit.face + 1;
      }
      if (!intensity) continue;
      double acc = 0.0;
      for (int sy = 0; sy < ss; ++sy)
        for (int sx = 0; sx < ss; ++sx) {
          const double uu = u - 0.5 + (sx + 0.5) / ss, vv = v - 0.5 + (sy + 0.5) / ss;
          Hit h;
          intersect(boxes, inv, o, R * Eigen::Vector3d((uu - cam.cx) / cam.fx, (vv - cam.cy) / cam.fy, 1.0), h);
          if (h.box < 0) continue;
          const Box& b = boxes[size_t(h.box)];
          const int axis = h.face / 2;
          const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
          const double tex = 0.6 * value_noise(h.local(a1), h.local(a2), 0.004, b.seed * 7 + uint32_t(h.face)) +
                             0.4 * value_noise(h.local(a1), h.local(a2), 0.015, b.seed * 13 + uint32_t(h.face));
          Eigen::Vector3d n = Eigen::Vector3d::Zero();
          n(axis) = (h.face % 2) ? 1.0 : -1.0;
          const double shade = 0.35 + 0.65 * std::max(0.0, (b.pose.linear() * n).dot(light));
          acc += 255.0 * b.albedo * shade * (0.45 + 0.55 * tex);
        }
      out.intensity.at<uint8_t>(v, u) = uint8_t(std::clamp(acc / (ss * ss), 0.0, 255.0));
    }
  }
  return out;
}

ShelfScene make_shelf_scene(uint32_t seed, bool fronts_at_the_edge) {
  std::mt19937 rng(seed);
  auto uni = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  ShelfScene s;
  const double yaw = uni(-4.0, 4.0) * M_PI / 180.0;
  s.cart_in_base = make_iso(Eigen::Vector3d(uni(0.72, 0.78), uni(-0.05, 0.05), 0.55),
                            Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix());
  const double D = 0.32, half_w = 0.45, wall = 0.018, rear_h = 0.42;
  auto add = [&](const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, float albedo) {
    Box b;
    b.pose = shift(s.cart_in_base, 0.5 * (lo + hi));
    b.half = 0.5 * (hi - lo);
    b.albedo = albedo;
    b.seed = uint32_t(s.boxes.size() + 1) * 977u + seed;
    s.boxes.push_back(b);
  };
  add({0, -half_w, -wall}, {D, half_w, 0}, 0.7f);                              // upper shelf board
  add({D, -half_w, -wall}, {D + wall, half_w, rear_h}, 0.6f);                  // rear board
  add({0, -half_w - wall, -0.45}, {D + wall, -half_w, 0.12}, 0.65f);           // right side board (low)
  add({0, half_w, -0.45}, {D + wall, half_w + wall, 0.12}, 0.65f);             // left side board (low)
  add({0, -half_w, -0.45 - wall}, {D, half_w, -0.45}, 0.7f);                   // lower shelf board
  add({D, -half_w, -0.45}, {D + wall, half_w, -wall}, 0.55f);                  // lower rear board
  add({-1.2, -2.0, -0.9}, {2.5, 2.0, -0.88}, 0.5f);                           // floor
  s.first_book = int(s.boxes.size());
  double y = -half_w + uni(0.02, 0.08);  // right end of the next book
  const int n = int(uni(8, 15));
  for (int i = 0; i < n; ++i) {
    const bool portrait = (i % 2 == 0) == (seed % 2 == 0);
    const double h = portrait ? uni(0.21, 0.26) : uni(0.15, 0.19);
    const double depth = portrait ? uni(0.15, 0.19) : uni(0.21, 0.26);
    const double t = uni(0.010, 0.035);
    if (y + t > half_w - 0.01) break;
    const double front = fronts_at_the_edge ? 0.01 : D - depth;
    add({front, y, 0}, {front + depth, y + t, h}, float(uni(0.35, 0.95)));
    if (i == 0) {
      s.rightmost_book = int(s.boxes.size()) - 1;
      s.true_corner_base = s.cart_in_base * Eigen::Vector3d(front, y, h);
    }
    y += t + uni(0.0, 0.003);
    ++s.num_books;
  }
  s.shelf_box_in_base = shift(s.cart_in_base, Eigen::Vector3d(0.5 * D, 0.0, 0.5 * 0.30));
  s.shelf_half_extent = Eigen::Vector3d(0.5 * D + 0.02, half_w, 0.5 * 0.30);

  // Stereo camera ~1.4 m from the shelf, above and in front of it.
  PinholeCamera cam;
  cam.width = 640;
  cam.height = 480;
  cam.fy = cam.fx = 240.0 / std::tan(22.5 * M_PI / 180.0);
  cam.cx = 319.5;
  cam.cy = 239.5;
  const Eigen::Vector3d pos(-0.40, -0.15, 1.30);
  const Eigen::Vector3d target = s.cart_in_base * Eigen::Vector3d(0.10, -0.15, 0.12);
  const Eigen::Vector3d z = (target - pos).normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d yv = z.cross(x);
  Eigen::Matrix3d R;
  R.col(0) = x;
  R.col(1) = yv;
  R.col(2) = z;
  cam.in_base = make_iso(pos, R);
  s.left = cam;
  s.right = cam;
  s.right.in_base = make_iso(pos + s.baseline_m * x, R);
  return s;
}

cv::Mat exact_disparity(const cv::Mat& depth, double fx, double baseline_m) {
  cv::Mat d(depth.size(), CV_32F);
  for (int y = 0; y < depth.rows; ++y)
    for (int x = 0; x < depth.cols; ++x) {
      const float z = depth.at<float>(y, x);
      d.at<float>(y, x) = std::isfinite(z) ? float(fx * baseline_m / z) : std::numeric_limits<float>::quiet_NaN();
    }
  return d;
}

}  // namespace bookgrasp::bws::test
