#include "services/eval_segmentation/range_scene.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <memory>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include <mujoco/mujoco.h>
#include <Eigen/Geometry>

#include "common/scene/mjcf_builder.h"
#include "common/scene/scene.h"
#include "common/scene/sim_model.h"
#include "common/sim_render/offscreen_renderer.h"
#include "common/sim_render/sensor_model.h"

namespace bookgrasp::eval_segmentation {
namespace {

struct VfsDeleter {
  void operator()(mjVFS* v) const {
    mj_deleteVFS(v);
    delete v;
  }
};
struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};

void add_file(mjVFS* vfs, const std::string& name, const void* data, size_t size) {
  if (mj_makeEmptyFileVFS(vfs, name.c_str(), static_cast<int>(size)) != 0)
    throw std::runtime_error("MuJoCo VFS: cannot add '" + name + "'");
  const int i = mj_findFileVFS(vfs, name.c_str());
  std::memcpy(vfs->filedata[i], data, size);
}

std::string num(double v) {
  std::ostringstream s;
  s.precision(9);
  s << v;
  return s.str();
}

// Cup (cylinder) and ball (sphere) on the upper shelf, in the free room right and left of the books.
// Returns the MJCF geoms (worldbody) and the number placed.
std::string curved_object_geoms(const scene::Scene& scene, const ground_truth_t& truth, int* placed) {
  *placed = 0;
  const Eigen::Isometry3d cart_inv = scene.cart_pose.inverse();
  double ymin = 1e9, ymax = -1e9;
  for (const book_truth_t& b : truth.books) {
    if (b.place != "upper_shelf") continue;
    for (const auto& c : b.corners_base) {
      const Eigen::Vector3d p = cart_inv * Eigen::Vector3d(c[0], c[1], c[2]);
      ymin = std::min(ymin, p.y());
      ymax = std::max(ymax, p.y());
    }
  }
  if (ymin > ymax) ymin = ymax = 0.0;  // no book on the shelf: objects around the middle
  const double half = scene.shelf_width_m / 2, margin = 0.008;
  struct Obj {
    const char* name;
    const char* type;
    double radius, half_height;
  };
  const Obj objs[2] = {{"evalseg_cup", "cylinder", 0.035, 0.05}, {"evalseg_ball", "sphere", 0.04, 0.0}};
  // The stereo camera looks along the shelf from the left: objects side by side along y would hide each
  // other, so the cup stands at the front and the ball 16 cm deeper, both in the first side with room.
  const double r = std::max(objs[0].radius, objs[1].radius);
  double y;
  if (ymin - margin - 2 * r >= -half + margin)
    y = ymin - margin - r;
  else if (ymax + margin + 2 * r <= half - margin)
    y = ymax + margin + r;
  else
    return "";
  std::ostringstream x;
  for (int k = 0; k < 2; ++k) {
    const Obj& o = objs[k];
    const double z = o.half_height > 0 ? o.half_height : o.radius;
    const Eigen::Vector3d p = scene.cart_pose * Eigen::Vector3d(0.04 + o.radius + 0.16 * k, y, z + 0.0005);
    x << "    <geom name=\"" << o.name << "\" type=\"" << o.type << "\" size=\"" << num(o.radius);
    if (o.half_height > 0) x << " " << num(o.half_height);
    x << "\" pos=\"" << num(p.x()) << " " << num(p.y()) << " " << num(p.z())
      << "\" material=\"evalseg_speckle_mat\" contype=\"0\" conaffinity=\"0\"/>\n";
    ++*placed;
  }
  return x.str();
}

const char* kAsset =
    "    <texture name=\"evalseg_speckle\" type=\"cube\" builtin=\"flat\" rgb1=\"0.85 0.45 0.25\" "
    "rgb2=\"0.85 0.45 0.25\" mark=\"random\" random=\"0.35\" markrgb=\"0.15 0.1 0.05\" width=\"512\" "
    "height=\"512\"/>\n"
    "    <material name=\"evalseg_speckle_mat\" texture=\"evalseg_speckle\" specular=\"0.1\"/>\n";

// Per-face description used while building the ground truth.
struct Face {
  std::string name;
  int owner = scene::kOwnerOther;
  int geom = -1;
  bool planar = false;
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double offset = 0.0;
};

int find_root(std::vector<int>& parent, int a) {
  while (parent[size_t(a)] != a) a = parent[size_t(a)] = parent[size_t(parent[size_t(a)])];
  return a;
}

// Face index (0..7) of a point on geom g and the face's description.
int face_of(const mjModel* m, const mjData* d, int g, const Eigen::Vector3d& p, Face* f) {
  const Eigen::Vector3d c(d->geom_xpos[3 * g], d->geom_xpos[3 * g + 1], d->geom_xpos[3 * g + 2]);
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) R(r, k) = d->geom_xmat[9 * g + 3 * r + k];
  const Eigen::Vector3d q = R.transpose() * (p - c);
  const mjtNum* s = m->geom_size + 3 * g;
  const char* axes[6] = {"-x", "+x", "-y", "+y", "-z", "+z"};
  switch (m->geom_type[g]) {
    case mjGEOM_BOX: {
      int best = 0;
      double bd = 1e9;
      for (int a = 0; a < 3; ++a) {
        const double dist = std::fabs(std::fabs(q(a)) - s[a]);
        if (dist < bd) {
          bd = dist;
          best = a;
        }
      }
      const int sign = q(best) >= 0 ? 1 : -1;
      if (f) {
        f->planar = true;
        f->normal = sign * R.col(best);
        f->offset = f->normal.dot(c) + s[best];
        f->name = axes[2 * best + (sign > 0)];
      }
      return 2 * best + (sign > 0);
    }
    case mjGEOM_CYLINDER: {
      const double cap = std::fabs(std::fabs(q.z()) - s[1]), side = std::fabs(q.head<2>().norm() - s[0]);
      if (cap < side) {
        const int sign = q.z() >= 0 ? 1 : -1;
        if (f) {
          f->planar = true;
          f->normal = sign * R.col(2);
          f->offset = f->normal.dot(c) + s[1];
          f->name = sign > 0 ? "cap+" : "cap-";
        }
        return sign > 0 ? 1 : 0;
      }
      if (f) f->name = "mantle";
      return 2;
    }
    case mjGEOM_PLANE:
      if (f) {
        f->planar = true;
        f->normal = R.col(2);
        f->offset = f->normal.dot(c);
        f->name = "plane";
      }
      return 0;
    case mjGEOM_SPHERE:
      if (f) f->name = "sphere";
      return 0;
    default:
      if (f) f->name = "mesh";
      return 0;
  }
}

}  // namespace

int RangeScene::rightmost_front_label() const {
  for (const book_truth_t& b : truth.books) {
    if (!b.rightmost) continue;
    const auto it = face_label.find("book_" + std::to_string(b.id) + "_pages:+z");
    return it == face_label.end() ? 0 : it->second;
  }
  return 0;
}

RangeScene render_range_scene(const RangeSceneOptions& o) {
  if (o.min_region_px < 1) throw std::invalid_argument("range scene: min_region_px must be >= 1");
  if (!(o.coplanar_max_angle_deg >= 0) || !(o.coplanar_max_offset_m >= 0) || !(o.max_depth_m > 0))
    throw std::invalid_argument("range scene: coplanar tolerances must be >= 0 and max_depth_m > 0");
  if (o.left_margin_px < 0) throw std::invalid_argument("range scene: left_margin_px must be >= 0");

  const scene::Scene sc = scene::load_scene(o.scene_file, o.seed);
  scene::SimModel sim = scene::SimModel::build(sc);
  RangeScene out;
  out.truth = sim.ground_truth(o.utime);

  // The model rendered: the simulator's, or a copy with the curved objects (static geoms, no joints:
  // the settled joint state of the simulator is copied into it).
  std::unique_ptr<mjModel, ModelDeleter> own_model;
  std::unique_ptr<mjData, DataDeleter> own_data;
  mjModel* m = sim.model();
  mjData* d = sim.data();
  if (o.curved_objects) {
    scene::MjcfDocument doc = scene::build_mjcf(sc);
    const std::string geoms = curved_object_geoms(sc, out.truth, &out.curved_objects_placed);
    const size_t a = doc.xml.find("  </asset>"), w = doc.xml.rfind("  </worldbody>");
    if (a == std::string::npos || w == std::string::npos)
      throw std::runtime_error("range scene: generated MJCF has no </asset> or </worldbody>");
    doc.xml.insert(w, geoms);
    doc.xml.insert(a, kAsset);
    std::unique_ptr<mjVFS, VfsDeleter> vfs(new mjVFS);
    mj_defaultVFS(vfs.get());
    add_file(vfs.get(), "scene.xml", doc.xml.data(), doc.xml.size());
    for (const auto& [name, bytes] : doc.files) add_file(vfs.get(), name, bytes.data(), bytes.size());
    char err[1000] = {0};
    own_model.reset(mj_loadXML("scene.xml", vfs.get(), err, sizeof err));
    if (!own_model)
      throw std::runtime_error(std::string("range scene: MuJoCo rejected the model with curved objects: ") + err);
    if (own_model->nq != m->nq) throw std::runtime_error("range scene: curved objects changed the joint layout");
    own_data.reset(mj_makeData(own_model.get()));
    std::copy(d->qpos, d->qpos + m->nq, own_data->qpos);
    mj_forward(own_model.get(), own_data.get());
    m = own_model.get();
    d = own_data.get();
  }

  sim_render::RendererSettings rs;
  for (const scene::CameraSpec* c : {&sc.stereo_left, &sc.stereo_right}) {
    rs.max_width = std::max(rs.max_width, c->width);
    rs.max_height = std::max(rs.max_height, c->height);
  }
  rs.shadows = sc.lighting.shadows;
  rs.shadow_size = sc.lighting.shadow_size;
  sim_render::OffscreenRenderer renderer(m, rs);
  const auto capture = [&](const scene::CameraSpec& c, bool depth_and_ids) {
    sim_render::RenderRequest req;
    req.camera = c.name;
    req.width = c.width;
    req.height = c.height;
    req.depth = req.segmentation = depth_and_ids;
    sim_render::RenderedView v = renderer.render(d, req);
    sim_render::SensorModel sensor;
    sensor.exposure_gain = c.exposure;
    sensor.noise_stddev = c.noise_stddev;
    v.rgb = sim_render::apply_sensor_model(v.rgb, sensor,
                                           sim_render::frame_seed(static_cast<int64_t>(o.seed), o.utime, c.name));
    return v;
  };
  sim_render::RenderedView left = capture(sc.stereo_left, true);
  const sim_render::RenderedView right = capture(sc.stereo_right, false);
  out.left_camera = left.camera;
  out.right_camera = right.camera;
  out.baseline_m = (left.camera.camera_in_base.translation() - right.camera.camera_in_base.translation()).norm();
  out.left_rgb = left.rgb;
  out.right_rgb = right.rgb;
  out.depth = left.depth;

  // Owner of every geom of the rendered model, by name through the simulator's model.
  std::vector<int> owner(size_t(m->ngeom), scene::kOwnerOther);
  std::vector<std::string> geom_name(size_t(m->ngeom));
  for (int g = 0; g < m->ngeom; ++g) {
    const char* n = mj_id2name(m, mjOBJ_GEOM, g);
    geom_name[size_t(g)] = n ? n : "geom" + std::to_string(g);
    const int sg = n ? mj_name2id(sim.model(), mjOBJ_GEOM, n) : -1;
    owner[size_t(g)] = sg >= 0 ? sim.geom_owner_id(sg) : scene::kOwnerOther;
  }

  // 1. Face key (geom * 8 + face) per pixel, -1 = unlabelled.
  const int H = left.depth.rows, W = left.depth.cols;
  cv::Mat key(H, W, CV_32S, cv::Scalar(-1));
  std::map<int, Face> faces;
  const sim_render::PinholeCamera& cam = left.camera;
  for (int y = 0; y < H; ++y) {
    const float* z = left.depth.ptr<float>(y);
    const int* gid = left.geom_id.ptr<int>(y);
    int* k = key.ptr<int>(y);
    for (int x = o.left_margin_px; x < W; ++x) {
      const int g = gid[x];
      if (g < 0 || g >= m->ngeom || !std::isfinite(z[x]) || z[x] > o.max_depth_m) continue;
      const Eigen::Vector3d p = cam.camera_in_base * (cam.ray(x, y) * double(z[x]));
      const int fi = face_of(m, d, g, p, nullptr);
      k[x] = g * 8 + fi;
      if (!faces.count(k[x])) {
        Face f;
        face_of(m, d, g, p, &f);
        f.name = geom_name[size_t(g)] + ":" + f.name;
        f.owner = owner[size_t(g)];
        f.geom = g;
        faces[k[x]] = f;
      }
    }
  }
  // 2. Union of touching coplanar faces of different geoms.
  std::map<int, int> dense;
  std::vector<int> keys;
  for (const auto& [k, f] : faces) {
    dense[k] = int(keys.size());
    keys.push_back(k);
  }
  std::vector<int> parent(keys.size());
  std::iota(parent.begin(), parent.end(), 0);
  const double cos_max = std::cos(o.coplanar_max_angle_deg * M_PI / 180.0);
  const auto try_merge = [&](int ka, int kb) {
    if (ka < 0 || kb < 0 || ka == kb) return;
    const Face& fa = faces[ka];
    const Face& fb = faces[kb];
    if (!fa.planar || !fb.planar || fa.geom == fb.geom) return;
    if (fa.normal.dot(fb.normal) < cos_max || std::fabs(fa.offset - fb.offset) > o.coplanar_max_offset_m) return;
    const int ra = find_root(parent, dense[ka]), rb = find_root(parent, dense[kb]);
    if (ra != rb) parent[size_t(std::max(ra, rb))] = std::min(ra, rb);
  };
  for (int y = 0; y < H; ++y) {
    const int* k = key.ptr<int>(y);
    const int* kd = y + 1 < H ? key.ptr<int>(y + 1) : nullptr;
    for (int x = 0; x < W; ++x) {
      if (x + 1 < W) try_merge(k[x], k[x + 1]);
      if (kd) try_merge(k[x], kd[x]);
    }
  }
  cv::Mat surface(H, W, CV_32S, cv::Scalar(0));  // union root + 1
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const int k = key.at<int>(y, x);
      if (k >= 0) surface.at<int>(y, x) = find_root(parent, dense[k]) + 1;
    }
  // 3. 4-connected pieces of every surface, small ones dropped, labels 1.. in raster order.
  cv::Mat comp(H, W, CV_32S, cv::Scalar(0));
  std::vector<int> comp_size;
  std::vector<cv::Point> stack;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const int s = surface.at<int>(y, x);
      if (s == 0 || comp.at<int>(y, x) != 0) continue;
      const int id = int(comp_size.size()) + 1;
      int n = 0;
      stack.assign(1, cv::Point(x, y));
      comp.at<int>(y, x) = id;
      while (!stack.empty()) {
        const cv::Point p = stack.back();
        stack.pop_back();
        ++n;
        const cv::Point nb[4] = {{p.x + 1, p.y}, {p.x - 1, p.y}, {p.x, p.y + 1}, {p.x, p.y - 1}};
        for (const cv::Point& q : nb) {
          if (q.x < 0 || q.y < 0 || q.x >= W || q.y >= H) continue;
          if (surface.at<int>(q) != s || comp.at<int>(q) != 0) continue;
          comp.at<int>(q) = id;
          stack.push_back(q);
        }
      }
      comp_size.push_back(n);
    }
  std::vector<int> final_label(comp_size.size() + 1, 0);
  for (size_t c = 0; c < comp_size.size(); ++c)
    if (comp_size[c] >= o.min_region_px) {
      GtRegion r;
      r.label = int(out.regions.size()) + 1;
      r.pixel_count = comp_size[c];
      out.regions.push_back(r);
      final_label[c + 1] = r.label;
    }
  out.gt_labels = cv::Mat(H, W, CV_32S, cv::Scalar(0));
  // Per region the face with most pixels names it; per face the region holding most of its pixels.
  std::map<std::pair<int, int>, int> count;  // (region, face key) -> pixels
  std::map<int, std::pair<int, int>> face_best;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const int l = final_label[size_t(comp.at<int>(y, x))];
      out.gt_labels.at<int>(y, x) = l;
      const int k = key.at<int>(y, x);
      if (k >= 0) ++count[{l, k}];
    }
  std::vector<int> best_face(out.regions.size() + 1, 0), best_n(out.regions.size() + 1, 0);
  for (const auto& [rk, n] : count) {
    const auto [l, k] = rk;
    if (l > 0 && n > best_n[size_t(l)]) {
      best_n[size_t(l)] = n;
      best_face[size_t(l)] = k;
    }
    auto& fb = face_best[k];
    if (n > fb.second || (l > 0 && fb.first == 0 && n == fb.second)) fb = {l, n};
  }
  for (GtRegion& r : out.regions) {
    const Face& f = faces[best_face[size_t(r.label)]];
    r.name = f.name;
    r.owner = f.owner;
    r.planar = f.planar;
  }
  for (const auto& [k, lb] : face_best) out.face_label[faces[k].name] = lb.first;
  return out;
}

cv::Mat colorize_labels(const cv::Mat& labels) {
  cv::Mat out(labels.size(), CV_8UC3, cv::Scalar(0, 0, 0));
  for (int y = 0; y < labels.rows; ++y)
    for (int x = 0; x < labels.cols; ++x) {
      const int l = labels.at<int>(y, x);
      if (l == 0) continue;
      uint32_t h = uint32_t(l) * 2654435761u;
      h ^= h >> 15;
      h *= 2246822519u;
      h ^= h >> 13;
      out.at<cv::Vec3b>(y, x) = cv::Vec3b(uchar(60 + (h & 0xff) % 196), uchar(60 + ((h >> 8) & 0xff) % 196),
                                          uchar(60 + ((h >> 16) & 0xff) % 196));
    }
  return out;
}

}  // namespace bookgrasp::eval_segmentation
