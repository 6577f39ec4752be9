#include "common/scene/scene.h"

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace bookgrasp::scene {

namespace {

constexpr double kPi = 3.14159265358979323846;
double deg(double d) { return d * kPi / 180.0; }

// A [lo, hi] pair from the file, checked against [min, max].
struct Range {
  double lo, hi;
};
Range get_range(const Config& c, const std::string& key, double min, double max) {
  const std::vector<double> v = c.get_vector(key, 2);
  if (!(v[0] <= v[1]) || v[0] < min || v[1] > max)
    throw ConfigError(c.source() + ": " + c.path_of(key) + " must be [lo, hi] with " + std::to_string(min) +
                      " <= lo <= hi <= " + std::to_string(max));
  return {v[0], v[1]};
}
double draw(Rng& rng, const Range& r) { return r.lo == r.hi ? r.lo : rng.uniform(r.lo, r.hi); }

Eigen::Vector3d get_vec3(const Config& c, const std::string& key) {
  const std::vector<double> v = c.get_vector(key, 3);
  return {v[0], v[1], v[2]};
}
Eigen::Vector3d get_rgb(const Config& c, const std::string& key) {
  Eigen::Vector3d v = get_vec3(c, key);
  for (int i = 0; i < 3; ++i)
    if (!(v[i] >= 0 && v[i] <= 1)) throw ConfigError(c.source() + ": " + c.path_of(key) + " must be 3 values in 0..1");
  return v;
}

Eigen::Isometry3d make_pose(const Eigen::Vector3d& t, const Eigen::Matrix3d& r) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = r;
  p.translation() = t;
  return p;
}
Eigen::Matrix3d rot_z(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix(); }
Eigen::Matrix3d rot_y(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix(); }
Eigen::Matrix3d rot_x(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix(); }

// An axis-aligned box in `frame` given by its min and max corners.
StaticBox box_in(const Eigen::Isometry3d& frame, const std::string& name, const std::string& owner,
                 const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const Eigen::Vector3d& rgb) {
  StaticBox b;
  b.name = name;
  b.owner = owner;
  b.pose = frame * make_pose(0.5 * (lo + hi), Eigen::Matrix3d::Identity());
  b.half_size = 0.5 * (hi - lo);
  b.rgb = rgb;
  return b;
}

Eigen::Vector3d hsv_to_rgb(double h, double s, double v) {
  const double c = v * s;
  const double hp = std::fmod(h * 6.0, 6.0);
  const double x = c * (1 - std::abs(std::fmod(hp, 2.0) - 1));
  Eigen::Vector3d rgb;
  if (hp < 1) rgb = {c, x, 0};
  else if (hp < 2) rgb = {x, c, 0};
  else if (hp < 3) rgb = {0, c, x};
  else if (hp < 4) rgb = {0, x, c};
  else if (hp < 5) rgb = {x, 0, c};
  else rgb = {c, 0, x};
  return rgb + Eigen::Vector3d::Constant(v - c);
}

// 2-D convex polygon (y, z) in the cart frame, for placing leaning books.
using Poly = std::array<Eigen::Vector2d, 4>;

Poly book_polygon(double cy, double cz, double w, double h, double lean) {
  Poly p;
  const double c = std::cos(lean), s = std::sin(lean);
  const double ys[4] = {-w / 2, w / 2, w / 2, -w / 2};
  const double zs[4] = {-h / 2, -h / 2, h / 2, h / 2};
  for (int i = 0; i < 4; ++i) p[i] = {cy + ys[i] * c - zs[i] * s, cz + ys[i] * s + zs[i] * c};
  return p;
}

// True if the polygons are closer than `gap` along some separating axis test (SAT).
bool too_close(const Poly& a, const Poly& b, double gap) {
  for (const Poly* poly : {&a, &b}) {
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector2d e = (*poly)[(i + 1) % 4] - (*poly)[i];
      const Eigen::Vector2d n(-e.y(), e.x());
      const Eigen::Vector2d u = n.normalized();
      double amin = 1e9, amax = -1e9, bmin = 1e9, bmax = -1e9;
      for (const auto& q : a) {
        amin = std::min(amin, u.dot(q));
        amax = std::max(amax, u.dot(q));
      }
      for (const auto& q : b) {
        bmin = std::min(bmin, u.dot(q));
        bmax = std::max(bmax, u.dot(q));
      }
      if (amax + gap <= bmin || bmax + gap <= amin) return false;
    }
  }
  return true;
}

}  // namespace

// ---- Rng ----

Rng::Rng(uint64_t seed) : engine_(seed) {}
uint64_t Rng::next() { return engine_(); }
double Rng::uniform01() { return static_cast<double>(engine_() >> 11) * (1.0 / 9007199254740992.0); }
double Rng::uniform(double lo, double hi) { return lo + (hi - lo) * uniform01(); }
double Rng::normal(double mean, double stddev) {
  double u1 = uniform01();
  while (u1 <= 0.0) u1 = uniform01();
  const double u2 = uniform01();
  return mean + stddev * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * kPi * u2);
}
int Rng::uniform_int(int lo, int hi) {
  if (hi <= lo) return lo;
  const uint64_t span = static_cast<uint64_t>(hi - lo) + 1;
  return lo + static_cast<int>(engine_() % span);
}
bool Rng::bernoulli(double p) { return uniform01() < p; }

// ---- geometry ----

std::array<Eigen::Vector3d, 8> book_corners(const Eigen::Isometry3d& pose, double width, double height,
                                            double depth) {
  std::array<Eigen::Vector3d, 8> c;
  for (int i = 0; i < 8; ++i) {
    const Eigen::Vector3d local((i & 1) ? depth / 2 : -depth / 2, (i & 2) ? width / 2 : -width / 2,
                                (i & 4) ? height / 2 : -height / 2);
    c[i] = pose * local;
  }
  return c;
}

Eigen::Vector3d stripe_end(const Scene& scene, const Eigen::Isometry3d& book_pose, double width, double height,
                           double depth) {
  // Stripe centre line in the cart frame: x = shelf depth (board face), z = stripe height.
  const Eigen::Isometry3d cart_inv = scene.cart_pose.inverse();
  const Eigen::Isometry3d in_cart = cart_inv * book_pose;
  const Eigen::Vector3d bottom = in_cart * Eigen::Vector3d(-depth / 2, -width / 2, -height / 2);
  const Eigen::Vector3d top = in_cart * Eigen::Vector3d(-depth / 2, -width / 2, height / 2);
  const double dz = top.z() - bottom.z();
  double t = dz != 0 ? (scene.stripe_height_m - bottom.z()) / dz : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const double y = bottom.y() + t * (top.y() - bottom.y());
  return scene.cart_pose * Eigen::Vector3d(scene.shelf_depth_m, y, scene.stripe_height_m);
}

std::string classify_place(const Scene& scene, const Eigen::Vector3d& position) {
  const Eigen::Vector3d c = scene.cart_pose.inverse() * position;
  const bool in_cart = c.x() > -0.02 && c.x() < scene.shelf_depth_m + 0.02 &&
                       std::abs(c.y()) < scene.shelf_width_m / 2 + 0.02;
  if (in_cart && c.z() > 0 && c.z() < 0.40) return "upper_shelf";
  if (in_cart && c.z() > -scene.lower_shelf_drop_m && c.z() < -0.02) return "lower_shelf";
  const Eigen::Vector3d h = scene.holder_pose.inverse() * position;
  if (std::abs(h.x()) < 0.25 && std::abs(h.y()) < 0.30 && h.z() > 0 && h.z() < 0.40) return "holder";
  return "other";
}

// ---- generation ----

Scene load_scene(const std::string& yaml_path, uint64_t seed) {
  const Config cfg = Config::load_file(yaml_path);
  const std::filesystem::path dir = std::filesystem::path(yaml_path).parent_path();
  return generate_scene(cfg, seed, dir.string());
}

Scene generate_scene(const Config& root, uint64_t seed, const std::string& base_dir) {
  Scene s;
  s.source = root.source();
  s.seed = seed;
  s.name = root.get<std::string>("name");
  Rng rng(seed);

  // robot
  {
    const Config c = root.child("robot");
    std::filesystem::path urdf = c.get<std::string>("urdf");
    if (urdf.is_relative() && !base_dir.empty()) urdf = std::filesystem::path(base_dir) / urdf;
    s.urdf_path = urdf.lexically_normal().string();
    for (double d : c.get_vector("initial_joints_deg", 7)) s.initial_joints.push_back(deg(d));
    s.initial_gripper_width_m = c.get_double("initial_gripper_width_m", 0.0, 0.06);
  }
  s.floor_z = root.get_double("floor.z_m", -3.0, 0.0);

  // cart
  const Config cc = root.child("cart");
  const Eigen::Vector3d cart_pos = get_vec3(cc, "position_m");
  s.cart_pose = make_pose(cart_pos, rot_z(deg(cc.get_double("yaw_deg", -90, 90))));
  s.shelf_width_m = cc.get_double("width_m", 0.3, 3.0);
  s.shelf_depth_m = cc.get_double("depth_m", 0.15, 1.0);
  const double t = cc.get_double("board_thickness_m", 0.005, 0.1);
  s.lower_shelf_drop_m = cc.get_double("lower_shelf_drop_m", 0.15, 1.0);
  const double rear_h = cc.get_double("rear_board_height_m", 0.1, 1.5);
  const double side_h = cc.get_double("side_panel_height_m", 0.0, 1.5);
  const double wheel = cc.get_double("wheel_clearance_m", 0.0, 0.5);
  const Eigen::Vector3d wood = get_rgb(cc, "color_rgb");
  const double W = s.shelf_width_m, D = s.shelf_depth_m, drop = s.lower_shelf_drop_m;
  const double floor_c = s.floor_z - cart_pos.z();
  if (-drop - t <= floor_c + wheel)
    throw ConfigError(root.source() + ": cart.lower_shelf_drop_m puts the lower shelf below the floor "
                      "(raise cart.position_m z or floor.z_m)");
  const Eigen::Isometry3d& C = s.cart_pose;
  s.boxes.push_back(box_in(C, "cart_upper_shelf", "cart", {0, -W / 2, -t}, {D + t, W / 2, 0}, wood));
  s.boxes.push_back(box_in(C, "cart_lower_shelf", "cart", {0, -W / 2, -drop - t}, {D + t, W / 2, -drop}, wood));
  s.boxes.push_back(box_in(C, "cart_rear_board", "cart", {D, -W / 2 - t, -drop - t}, {D + t, W / 2 + t, rear_h},
                           wood * 0.9));
  s.boxes.push_back(
      box_in(C, "cart_side_right", "cart", {0, -W / 2 - t, floor_c + wheel}, {D + t, -W / 2, side_h}, wood * 0.8));
  s.boxes.push_back(
      box_in(C, "cart_side_left", "cart", {0, W / 2, floor_c + wheel}, {D + t, W / 2 + t, side_h}, wood * 0.8));

  // stripe
  {
    const Config c = root.child("stripe");
    s.stripe_height_m = c.get_double("height_m", 0.01, rear_h);
    s.stripe_thickness_m = c.get_double("thickness_m", 0.002, 0.2);
    const double h = s.stripe_height_m, th = s.stripe_thickness_m;
    s.boxes.push_back(
        box_in(C, "stripe", "stripe", {D - 0.001, -W / 2, h - th / 2}, {D, W / 2, h + th / 2}, get_rgb(c, "color_rgb")));
  }

  // holder: base plate, inclined back plate, ledge with a lip
  const Config hc = root.child("holder");
  s.holder_pose = make_pose(get_vec3(hc, "position_m"), rot_z(deg(hc.get_double("yaw_deg", -180, 180))));
  {
    const Eigen::Vector3d base = get_vec3(hc, "base_size_m");
    const double incline = deg(hc.get_double("incline_deg", 0, 45));
    const double back_h = hc.get_double("back_height_m", 0.05, 1.0);
    const double back_t = hc.get_double("back_thickness_m", 0.002, 0.1);
    const double ledge = hc.get_double("ledge_depth_m", 0.01, 0.2);
    const double lip = hc.get_double("lip_height_m", 0.0, 0.1);
    // The ledge (with its lip and leg) may reach beyond the back plate's right end (-y): a book placed there
    // with the gripper's back finger beyond the plate stands on it with its whole bottom.
    const double ext = hc.get_double("ledge_extension_right_m", 0.0, 0.5);
    const Eigen::Vector3d rgb = get_rgb(hc, "color_rgb");
    const Eigen::Isometry3d& H = s.holder_pose;
    s.boxes.push_back(box_in(H, "holder_base", "holder", {-base.x() / 2, -base.y() / 2, 0},
                             {base.x() / 2, base.y() / 2, base.z()}, rgb));
    // Back plate frame P: origin at its bottom front edge, x = plate normal (away from the robot),
    // z = up along the plate. Its bottom front edge sits on the base plate, 3 cm from the rear end.
    const Eigen::Vector3d edge(base.x() / 2 - 0.03 - back_h * std::sin(incline), 0, base.z() + ledge * std::sin(incline));
    const Eigen::Isometry3d P = H * make_pose(edge, rot_y(incline));
    s.boxes.push_back(box_in(P, "holder_back", "holder", {0, -base.y() / 2, 0}, {back_t, base.y() / 2, back_h}, rgb));
    const double right = -base.y() / 2 - ext;
    s.boxes.push_back(box_in(P, "holder_ledge", "holder", {-ledge, right, -0.012}, {0, base.y() / 2, 0}, rgb));
    s.boxes.push_back(box_in(P, "holder_lip", "holder", {-ledge, right, 0}, {-ledge + 0.008, base.y() / 2, lip}, rgb));
    // Leg under the ledge down to the base plate.
    s.boxes.push_back(box_in(H, "holder_leg", "holder", {edge.x() - ledge * std::cos(incline) - 0.01, right, 0},
                             {edge.x(), base.y() / 2, edge.z() - 0.012}, rgb * 0.9));
    s.holder_support_pose = P;
    // Marker on the back plate's front face.
    const Config mc = root.child("markers.holder");
    s.holder_marker.name = "holder_marker";
    s.holder_marker.id = mc.get_int("id", 0, 586);
    s.holder_marker.size_m = mc.get_double("size_m", 0.01, 0.5);
    const double my = mc.get_double("y_m", -1, 1), mup = mc.get_double("up_m", 0, 1);
    Eigen::Matrix3d mr;
    mr.col(0) = -Eigen::Vector3d::UnitY();
    mr.col(1) = Eigen::Vector3d::UnitZ();
    mr.col(2) = -Eigen::Vector3d::UnitX();
    s.holder_marker.pose = P * make_pose({-0.001, my, mup}, mr);
  }

  // cart marker on the rear board's front face
  {
    const Config mc = root.child("markers.cart");
    s.cart_marker.name = "cart_marker";
    s.cart_marker.id = mc.get_int("id", 0, 586);
    s.cart_marker.size_m = mc.get_double("size_m", 0.01, 0.5);
    Eigen::Matrix3d mr;
    mr.col(0) = -Eigen::Vector3d::UnitY();
    mr.col(1) = Eigen::Vector3d::UnitZ();
    mr.col(2) = -Eigen::Vector3d::UnitX();
    s.cart_marker.pose =
        C * make_pose({D - 0.001, mc.get_double("y_m", -W / 2, W / 2), mc.get_double("z_m", 0, rear_h)}, mr);
  }

  // screen
  {
    const Config c = root.child("screen");
    const Eigen::Vector3d size = get_vec3(c, "size_m");
    const Eigen::Matrix3d r = rot_z(deg(c.get_double("yaw_deg", -180, 180))) * rot_y(deg(c.get_double("tilt_deg", -45, 45)));
    StaticBox b;
    b.name = "screen";
    b.owner = "screen";
    b.pose = make_pose(get_vec3(c, "position_m"), r);
    b.half_size = size / 2;
    b.rgb = get_rgb(c, "color_rgb");
    s.boxes.push_back(b);
  }

  // books
  {
    const Config c = root.child("books");
    const std::vector<int> count = c.get<std::vector<int>>("count");
    if (count.size() != 2 || count[0] < 1 || count[1] < count[0] || count[1] > 60)
      throw ConfigError(root.source() + ": " + c.path_of("count") + " must be [min, max] with 1 <= min <= max <= 60");
    const double p_portrait = c.get_double("first_portrait_probability", 0, 1);
    const Range offset = get_range(c, "rightmost_offset_m", 0, W);
    const Range width = get_range(c, "width_m", 0.003, 0.2);
    const Range ph = get_range(c, "portrait_height_m", 0.05, 1.0);
    const Range pr = get_range(c, "portrait_depth_ratio", 0.2, 3.0);
    const Range lh = get_range(c, "landscape_height_m", 0.05, 1.0);
    const Range lr = get_range(c, "landscape_depth_ratio", 0.2, 3.0);
    const double max_depth = c.get_double("max_depth_m", 0.05, D - 0.005);
    const double lean = deg(c.get_double("lean_deg", 0, 15));
    const Range depth_off = get_range(c, "depth_offset_m", 0, D);
    const Range gap = get_range(c, "gap_m", 0, 0.05);
    const Range sat = get_range(c, "cover_saturation", 0, 1);
    const Range val = get_range(c, "cover_value", 0, 1);
    const Eigen::Vector3d page = get_rgb(c, "page_rgb");
    const double page_jitter = c.get_double("page_rgb_jitter", 0, 0.5);
    const double p_stamp = c.get_double("stamp_probability", 0, 1);
    const Range stamp_d = get_range(c, "stamp_diameter_m", 0.001, 0.2);
    const double density = root.get_double("physics.book_density_kg_m3", 50, 5000);

    const int n = rng.uniform_int(count[0], count[1]);
    bool portrait = rng.bernoulli(p_portrait);
    const double right_end = -W / 2 + draw(rng, offset);
    std::vector<Poly> placed;
    static const Eigen::Vector3d inks[] = {{0.12, 0.18, 0.55}, {0.65, 0.10, 0.12}, {0.35, 0.12, 0.45}, {0.1, 0.1, 0.1}};
    for (int i = 0; i < n; ++i) {
      Book b;
      b.id = i;
      b.portrait = portrait;
      b.width_m = draw(rng, width);
      b.height_m = portrait ? draw(rng, ph) : draw(rng, lh);
      b.depth_m = std::min(max_depth, b.height_m * (portrait ? draw(rng, pr) : draw(rng, lr)));
      double a = rng.uniform(-lean, lean);
      if (i == 0) a = -std::abs(a);  // nothing on its right: the right-most book leans left (top to +y)
      b.lean_rad = a;
      const double g = draw(rng, gap);
      const double cz = b.width_m / 2 * std::abs(std::sin(a)) + b.height_m / 2 * std::cos(a);
      // Place: right side at right_end for the first book; others as far right as the neighbours allow.
      Poly p0 = book_polygon(0, cz, b.width_m, b.height_m, a);
      double ymin0 = 1e9, ymax0 = -1e9;
      for (const auto& q : p0) {
        ymin0 = std::min(ymin0, q.x());
        ymax0 = std::max(ymax0, q.x());
      }
      double cy = right_end - ymin0;
      if (!placed.empty()) {
        double prev_max = -1e9;
        for (const auto& poly : placed)
          for (const auto& q : poly) prev_max = std::max(prev_max, q.x());
        const double c_hi = prev_max + g - ymin0;  // clear of everything (bounding boxes apart)
        double best = -1e9;
        for (const auto& poly : placed) {
          double lo = 0.25 * (poly[0].x() + poly[1].x() + poly[2].x() + poly[3].x());  // overlapping
          double hi = c_hi;
          if (!too_close(book_polygon(lo, cz, b.width_m, b.height_m, a), poly, g)) continue;
          for (int it = 0; it < 40; ++it) {
            const double mid = 0.5 * (lo + hi);
            if (too_close(book_polygon(mid, cz, b.width_m, b.height_m, a), poly, g)) lo = mid;
            else hi = mid;
          }
          best = std::max(best, hi);
        }
        cy = best > -1e8 ? best : c_hi;
      }
      if (cy + ymax0 > W / 2 - 0.003) break;  // shelf full
      placed.push_back(book_polygon(cy, cz, b.width_m, b.height_m, a));
      double off = draw(rng, depth_off);
      off = std::min(off, D - 0.004 - b.depth_m);
      b.pose = C * make_pose({std::max(0.0, off) + b.depth_m / 2, cy, cz}, rot_x(a));
      b.mass_kg = density * b.width_m * b.height_m * b.depth_m;
      b.cover_rgb = hsv_to_rgb(rng.uniform01(), draw(rng, sat), draw(rng, val));
      for (int k = 0; k < 3; ++k) b.page_rgb[k] = std::clamp(page[k] + rng.uniform(-page_jitter, page_jitter), 0.0, 1.0);
      b.texture_seed = rng.next();
      while (rng.bernoulli(b.stamps.size() < 1 ? p_stamp : p_stamp * 0.3)) {
        Stamp st;
        st.u = rng.uniform(0.2, 0.8);
        st.v = rng.uniform(0.1, 0.9);
        st.diameter_m = draw(rng, stamp_d);
        st.rgb = inks[rng.uniform_int(0, 3)];
        st.round = rng.bernoulli(0.6);
        b.stamps.push_back(st);
        if (b.stamps.size() >= 3) break;
      }
      s.books.push_back(b);
      portrait = !portrait;
    }
  }

  // lighting
  {
    const Config c = root.child("lighting");
    const double az = deg(draw(rng, get_range(c, "azimuth_deg", -180, 180)));
    const double el = deg(draw(rng, get_range(c, "elevation_deg", 5, 90)));
    const Eigen::Vector3d to_light(-std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    s.lighting.direction = -to_light.normalized();
    s.lighting.intensity = draw(rng, get_range(c, "intensity", 0, 1));
    s.lighting.ambient = draw(rng, get_range(c, "ambient", 0, 1));
    s.lighting.shadows = c.get<bool>("shadows");
    s.lighting.shadow_size = c.get_int("shadow_size", 64, 8192);
  }

  // cameras
  {
    const Config c = root.child("cameras.stereo");
    const Eigen::Vector3d pos = get_vec3(c, "position_m");
    const Eigen::Vector3d look = get_vec3(c, "look_at_m");
    const Eigen::Vector3d z = (look - pos).normalized();
    if ((look - pos).norm() < 1e-3 || std::abs(z.z()) > 0.999)
      throw ConfigError(root.source() + ": cameras.stereo.look_at_m must differ from position_m and not be straight "
                        "above or below it");
    const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
    const Eigen::Vector3d y = z.cross(x);
    Eigen::Matrix3d r;
    r << x, y, z;
    s.stereo_baseline_m = c.get_double("baseline_m", 0.01, 1.0);
    CameraSpec cam;
    cam.fovy_rad = deg(c.get_double("fovy_deg", 5, 150));
    cam.width = c.get_int("width", 16, 8192);
    cam.height = c.get_int("height", 16, 8192);
    cam.noise_stddev = c.get_double("noise_stddev", 0, 100);
    cam.exposure = draw(rng, get_range(c, "exposure", 0.05, 10));
    s.stereo_left = cam;
    s.stereo_left.name = "stereo_left";
    s.stereo_left.pose = make_pose(pos, r);
    s.stereo_right = cam;
    s.stereo_right.name = "stereo_right";
    s.stereo_right.pose = make_pose(pos + s.stereo_baseline_m * x, r);
  }
  {
    const Config c = root.child("cameras.hand");
    s.hand_camera.name = "hand_camera";
    s.hand_camera.fovy_rad = deg(c.get_double("fovy_deg", 5, 150));
    s.hand_camera.width = c.get_int("width", 16, 8192);
    s.hand_camera.height = c.get_int("height", 16, 8192);
    s.hand_camera.noise_stddev = c.get_double("noise_stddev", 0, 100);
    s.hand_camera.exposure = draw(rng, get_range(c, "exposure", 0.05, 10));
  }

  // physics
  {
    const Config c = root.child("physics");
    Physics& p = s.physics;
    p.timestep_s = c.get_double("timestep_s", 1e-4, 0.01);
    p.impratio = c.get_double("impratio", 1, 1000);
    p.noslip_iterations = c.has("noslip_iterations") ? c.get_int("noslip_iterations", 0, 1000) : 0;
    p.settle_time_s = c.get_double("settle_time_s", 0, 10);
    p.arm_kp = c.get_vector("arm_kp", 7);
    p.arm_damping = c.get_vector("arm_damping", 7);
    for (int i = 0; i < 7; ++i)
      if (!(p.arm_kp[i] > 0) || !(p.arm_damping[i] >= 0))
        throw ConfigError(root.source() + ": physics.arm_kp must be > 0 and physics.arm_damping >= 0");
    p.arm_armature = c.get_double("arm_armature", 0, 100);
    p.gripper_kp = c.get_double("gripper_kp", 1, 1e6);
    p.gripper_damping = c.get_double("gripper_damping", 0, 1e5);
    p.gripper_max_force_n = c.get_double("gripper_max_force_n", 1, 1000);
    p.finger_friction = c.get_double("finger_friction", 0, 5);
    auto solref = [&](const char* key, std::vector<double>& v) {
      v = c.get_vector(key, 2);
      if (!(v[0] >= 2 * p.timestep_s && v[0] < 10 && v[1] > 0 && v[1] < 100))
        throw ConfigError(root.source() + ": physics." + key +
                          " must be [time constant s in [2 x timestep_s = " + std::to_string(2 * p.timestep_s) +
                          ", 10) (MuJoCo raises a shorter one to that), damping ratio in (0, 100)]");
    };
    solref("gripper_coupling_solref", p.gripper_coupling_solref);
    solref("finger_solref", p.finger_solref);
    p.finger_solimp = c.get_vector("finger_solimp", 3);
    if (const auto& v = p.finger_solimp; !(v[0] > 0 && v[0] <= v[1] && v[1] < 1 && v[2] > 0 && v[2] < 1))
      throw ConfigError(root.source() +
                        ": physics.finger_solimp must be [dmin, dmax, width m] with 0 < dmin <= "
                        "dmax < 1 and 0 < width < 1");
    p.book_friction = c.get_double("book_friction", 0, 5);
    p.shelf_friction = c.get_double("shelf_friction", 0, 5);
    p.book_density_kg_m3 = c.get_double("book_density_kg_m3", 50, 5000);
  }
  {
    const Config c = root.child("render");
    s.render.offscreen_width = c.get_int("offscreen_width", 64, 8192);
    s.render.offscreen_height = c.get_int("offscreen_height", 64, 8192);
    s.render.offsamples = c.get_int("offsamples", 0, 16);
    s.render.page_px_per_mm = c.get_double("page_px_per_mm", 0.5, 20);
    s.render.page_line_contrast = c.get_double("page_line_contrast", 0, 1);
    if (s.render.offscreen_width < s.stereo_left.width || s.render.offscreen_height < s.stereo_left.height ||
        s.render.offscreen_width < s.hand_camera.width || s.render.offscreen_height < s.hand_camera.height)
      throw ConfigError(root.source() + ": render.offscreen_width/height must be at least the camera resolutions");
  }
  root.require_all_read();
  return s;
}

}  // namespace bookgrasp::scene
