#include "services/coordinator/cycle_geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "common/grasp_frame.h"

namespace bookgrasp {
namespace {

Eigen::Vector3d vec3(const Config& c, const std::string& key, double limit = 5.0) {
  const std::vector<double> v = c.get_vector(key, 3);
  const Eigen::Vector3d e(v[0], v[1], v[2]);
  if (!e.allFinite() || e.norm() > limit)
    throw ConfigError(c.source() + ": " + c.path_of(key) + " must be finite and within " + std::to_string(limit) +
                      " m");
  return e;
}

/// A width or offset the corner servo measured (<= 0 or not finite: not measured).
bool measured(double v) {
  return std::isfinite(v) && v > 0;
}

}  // namespace

CycleGeometry CycleGeometry::from_config(const Config& c) {
  CycleGeometry g;
  g.grasp_origin_in_marker = vec3(c, "cart.grasp_origin_in_marker_m");
  g.shelf_left_y = c.get_double("cart.shelf_left_y_m", -3, 3);
  g.shelf_right_y = c.get_double("cart.shelf_right_y_m", -3, 3);
  if (g.shelf_right_y <= g.shelf_left_y)
    throw ConfigError(c.source() + ": " + c.path_of("cart.shelf_right_y_m") + " must be right of (greater than) " +
                      c.path_of("cart.shelf_left_y_m"));
  g.stripe_start = vec3(c, "servo.stripe_start_grasp_m");
  g.stripe_fixed_depth = c.get_double("servo.stripe_fixed_depth_m", 0.02, 1.0);
  g.stripe_left_limit_y = c.get_double("servo.stripe_left_limit_y_m", g.shelf_left_y, g.shelf_right_y);
  if (g.stripe_left_limit_y >= g.stripe_start.y())
    throw ConfigError(c.source() + ": " + c.path_of("servo.stripe_left_limit_y_m") +
                      " must be left of (less than) the Y of " + c.path_of("servo.stripe_start_grasp_m"));
  g.bwh_start_z = c.get_double("servo.bwh_start_z_m", -1.0, 0.0);
  g.bwh_start_offset_x = c.get_double("servo.bwh_start_offset_x_m", -0.3, 0.3);
  g.book_front_z = c.get_double("servo.book_front_z_m", -0.2, 0.3);
  g.grasp_offset_x = c.get_double("grasp.offset_x_m", -0.1, 0.1);
  g.grasp_offset_y = c.get_double("grasp.offset_y_m", -0.1, 0.1);
  g.insertion_depth = c.get_double("grasp.insertion_depth_m", 0.0, 0.2);
  g.width_left_clearance = c.get_double("grasp.width_left_clearance_m", 0.0, 0.05);
  g.left_plate_on_neighbour = c.get<bool>("grasp.left_plate_on_neighbour");
  g.plate_thickness = c.get_double("grasp.plate_thickness_m", 0.0, 0.05);
  g.left_plate_min_clearance = c.get_double("grasp.left_plate_min_clearance_m", 0.0, 0.05);
  g.more_than_the_book = c.get_double("grasp.more_than_the_book_m", 0.0, 0.05);
  g.retry_left_clearance = c.get_double("grasp.retry_left_clearance_m", 0.0005, 0.05);  // > 0: a narrower opening
  g.split_fore_edge_gap = c.get_double("grasp.split_fore_edge_gap_m", 0.0, 0.01);
  g.palm_half_width = c.get_double("grasp.palm_half_width_m", 0.0, 0.2);
  g.right_panel_clearance = c.get_double("grasp.right_panel_clearance_m", 0.0, 0.05);
  g.right_plate_min_clearance = c.get_double("grasp.right_plate_min_clearance_m", 0.0, 0.05);
  g.palm_behind_tcp = c.get_double("grasp.palm_behind_tcp_m", 0.0, 0.2);
  g.min_insertion_depth = c.get_double("grasp.min_insertion_depth_m", 0.0, g.insertion_depth);
  g.side_panel_front_z = c.get_double("cart.side_panel_front_z_m", -0.2, 0.3);
  g.pre_grasp_distance = c.get_double("grasp.pre_grasp_distance_m", 0.01, 0.5);
  g.deep_front_z = c.get_double("grasp.deep_front_z_m", -0.2, 0.36);
  g.extract_lift = c.get_double("grasp.extract_lift_m", 0.0, 0.5);
  g.extract_retreat = c.get_double("grasp.extract_retreat_m", 0.0, 1.0);
  g.extract_lift_out = c.get_double("grasp.extract_lift_out_m", 0.0, 0.3);
  g.holder_support_in_marker = vec3(c, "holder.support_origin_in_marker_m");
  g.holder_place_tcp = vec3(c, "holder.place_tcp_in_support_m");
  const Eigen::Vector3d x = vec3(c, "holder.gripper_x_in_support"), y = vec3(c, "holder.gripper_y_in_support");
  if (std::abs(x.norm() - 1) > 1e-6 || std::abs(y.norm() - 1) > 1e-6 || std::abs(x.dot(y)) > 1e-6)
    throw ConfigError(c.source() + ": " + c.path_of("holder.gripper_x_in_support") + " and " +
                      c.path_of("holder.gripper_y_in_support") + " must be orthogonal unit vectors");
  g.holder_gripper_axes.col(0) = x;
  g.holder_gripper_axes.col(1) = y;
  g.holder_gripper_axes.col(2) = x.cross(y);
  g.holder_pre_place_offset = vec3(c, "holder.pre_place_offset_m", 1.0);
  g.holder_place_descent = c.get_double("holder.place_descent_m", 0.0, 0.5);
  g.holder_place_guard = c.get_double("holder.place_guard_m", 0.0, 0.1);
  g.holder_retreat = c.get_double("holder.retreat_m", 0.02, 0.6);
  g.holder_regrasp_lower = c.get_double("holder.regrasp_lower_m", 0.0, 0.03);
  g.holder_regrasp_min_height = c.get_double("holder.regrasp_min_height_m", 0.0, 0.5);
  g.lower_drop = c.get_double("lower_shelf.drop_m", 0.1, 1.5);
  g.lower_front_z = c.get_double("lower_shelf.front_z_m", -0.2, 0.5);
  g.lower_first_right_y = c.get_double("lower_shelf.first_right_y_m", -3, 3);
  g.lower_gap = c.get_double("lower_shelf.gap_m", 0.0, 0.1);
  g.lower_release_opening = c.get_double("lower_shelf.release_opening_m", 0.0, 0.06);
  if (g.lower_release_opening > 0 && g.lower_gap < g.plate_thickness + 0.5 * g.lower_release_opening)
    throw ConfigError(c.source() + ": " + c.path_of("lower_shelf.gap_m") + " (" + std::to_string(g.lower_gap) +
                      ") must be at least " + c.path_of("grasp.plate_thickness_m") + " + " +
                      c.path_of("lower_shelf.release_opening_m") + " / 2 (" +
                      std::to_string(g.plate_thickness + 0.5 * g.lower_release_opening) +
                      "): the right plate would push the book placed before over");
  g.lower_left_y = c.get_double("lower_shelf.left_y_m", -3, 3);
  if (g.lower_first_right_y <= g.lower_left_y)
    throw ConfigError(c.source() + ": " + c.path_of("lower_shelf.first_right_y_m") + " must be right of " +
                      c.path_of("lower_shelf.left_y_m"));
  g.lower_retry_shift = c.get_double("lower_shelf.retry_shift_m", 0.0, 0.2);
  g.lower_pre_place_offset = vec3(c, "lower_shelf.pre_place_offset_m", 1.0);
  g.lower_retreat = c.get_double("lower_shelf.retreat_m", 0.02, 1.0);
  g.lower_place_guard = c.get_double("lower_shelf.place_guard_m", 0.0, 0.1);
  g.lower_shelf_gap = c.get_double("lower_shelf.gap_to_upper_shelf_m", 0.0, 1.5);
  g.held_top_above_tcp = c.get_double("lower_shelf.held_box_top_above_tcp_m", -0.2, 0.2);
  g.lower_book_clearance = c.get_double("lower_shelf.book_clearance_m", 0.0, 0.5);
  g.place_clearance = c.get_double("place_clearance_m", 0.0, 0.05);
  return g;
}

Eigen::Isometry3d cart_grasp_frame(const Eigen::Isometry3d& m, const CycleGeometry& g) {
  // AprilTag z points into the tag, i.e. into the rear board = into the shelf.
  Eigen::Isometry3d f = grasp_frame_in_base(m.linear().col(2), Eigen::Vector3d::Zero());
  f.translation() = m.translation() + f.linear() * g.grasp_origin_in_marker;
  return f;
}

Eigen::Isometry3d holder_support_frame(const Eigen::Isometry3d& m, const CycleGeometry& g) {
  Eigen::Isometry3d s = Eigen::Isometry3d::Identity();
  s.linear().col(0) = m.linear().col(2);   // into the back plate
  s.linear().col(1) = -m.linear().col(0);  // left along the plate (tag x is right)
  s.linear().col(2) = -m.linear().col(1);  // up along the plate (tag y is down)
  s.translation() = m * g.holder_support_in_marker;
  return s;
}

Eigen::Isometry3d pose_in_grasp_frame(const Eigen::Isometry3d& f, const Eigen::Vector3d& p) {
  Eigen::Isometry3d t = f;
  t.translation() = f * p;
  return t;
}

Eigen::Isometry3d stripe_start_pose(const Eigen::Isometry3d& f, const CycleGeometry& g) {
  return pose_in_grasp_frame(f, g.stripe_start);
}

Eigen::Isometry3d bwh_start_pose(const Eigen::Isometry3d& f, const Eigen::Vector3d& start, const CycleGeometry& g) {
  return pose_in_grasp_frame(f, Eigen::Vector3d(start.x() + g.bwh_start_offset_x, start.y(), g.bwh_start_z));
}

double servo_standoff(double front_z, const CycleGeometry& g) {
  return std::max(0.02, front_z - g.bwh_start_z);
}

std::vector<Eigen::Isometry3d> extract_moves(const Eigen::Isometry3d& here, const Eigen::Isometry3d& grasp_frame,
                                             double tcp_height, double grasp_tcp_z, const CycleGeometry& g) {
  const Eigen::Isometry3d to_grasp = grasp_frame.inverse();
  // How far one metre along the gripper's own axis moves the TCP along the grasp axis (books lean a few
  // degrees, so about 1; never below 0.5, so a strange posture cannot make the move run away).
  const auto along = [&](const Eigen::Isometry3d& pose, int axis) {
    return std::max(0.5, std::abs((to_grasp.linear() * pose.linear().col(axis))(axis)));
  };
  const Eigen::Vector3d at = to_grasp * here.translation();
  const double up = std::max(0.0, tcp_height + g.extract_lift - at.x());
  const double lift_out = std::max(0.0, at.z() - (grasp_tcp_z - g.extract_lift_out));
  const Eigen::Isometry3d lifted =
      move_along_own_axes(here, Eigen::Vector3d(up / along(here, 0), 0, -lift_out / along(here, 2)));
  const double out = (to_grasp * lifted.translation()).z() - (grasp_tcp_z - g.extract_retreat);
  return {lifted, move_along_own_axes(lifted, Eigen::Vector3d(0, 0, -std::max(0.0, out) / along(lifted, 2)))};
}

Eigen::Isometry3d move_along_own_axes(const Eigen::Isometry3d& pose, const Eigen::Vector3d& d) {
  Eigen::Isometry3d t = pose;
  t.translation() += pose.linear() * d;
  return t;
}

Eigen::Isometry3d grasp_pose(const Eigen::Isometry3d& gp, const CycleGeometry& g) {
  return move_along_own_axes(gp, Eigen::Vector3d(g.grasp_offset_x, g.grasp_offset_y, g.insertion_depth));
}

PlateOpening plate_opening(const ForeEdges& edges, double open_width, const CycleGeometry& g) {
  const PlateOpening full{open_width, g.grasp_offset_y};
  if (!measured(edges.front_width)) return full;
  double left = 0;  // the left plate's inner face, left of GP
  if (g.left_plate_on_neighbour && measured(edges.neighbour_offset) && measured(edges.neighbour_width))
    left = std::max(edges.neighbour_offset + 0.5 * edges.neighbour_width - 0.5 * g.plate_thickness,
                    edges.front_width + g.left_plate_min_clearance);
  else if (g.width_left_clearance > 0)
    left = edges.front_width + g.width_left_clearance;
  else
    return full;
  const double right = 0.5 * open_width + g.grasp_offset_y;  // right plate's inner face, right of GP
  const double width = right + left;
  if (width >= open_width) return full;
  return {width, right - 0.5 * width};
}

PlateOpening plate_opening_after_more_than_the_book(const ForeEdges& edges, double open_width, const CycleGeometry& g) {
  CycleGeometry narrow = g;
  narrow.left_plate_on_neighbour = false;
  narrow.width_left_clearance = g.retry_left_clearance;
  return plate_opening(edges, open_width, narrow);
}

double palm_over_right_panel(const PlateOpening& o, double gp_y, const CycleGeometry& g) {
  if (g.palm_half_width <= 0 || !std::isfinite(gp_y)) return 0.0;
  return gp_y + o.offset_y + g.palm_half_width + g.right_panel_clearance - g.shelf_right_y;
}

PlateOpening plate_opening_clear_of_right_panel(const PlateOpening& o, double gp_y, double open_width,
                                                const CycleGeometry& g) {
  const double over = palm_over_right_panel(o, gp_y, g);
  if (over <= 0) return o;
  // The right plate's inner face (offset_y + width / 2 right of GP) stays right_plate_min_clearance right of GP; a
  // narrowed opening widens on the left (up to open_width) where that alone would stop the palm short of clear.
  const double wanted = o.offset_y - over;
  const double width = std::max(o.width, std::min(open_width, 2.0 * (g.right_plate_min_clearance - wanted)));
  const double lowest = std::min(o.offset_y, g.right_plate_min_clearance - 0.5 * width);
  return {width, std::max(wanted, lowest)};
}

PlateGrasp plate_grasp_clear_of_right_panel(const PlateOpening& o, const Eigen::Vector3d& gp, double open_width,
                                            const CycleGeometry& g) {
  if (palm_over_right_panel(o, gp.y(), g) <= 0) return {o, g.insertion_depth};
  if (g.palm_behind_tcp > 0 && std::isfinite(gp.z())) {
    // The palm's face at GP.z + insertion - palm_behind_tcp; the right plate's outer face o.width / 2 +
    // plate_thickness right of the TCP.
    const double palm_in_front = g.side_panel_front_z - g.right_panel_clearance + g.palm_behind_tcp - gp.z();
    const double plate_over =
        gp.y() + o.offset_y + 0.5 * o.width + g.plate_thickness + g.right_panel_clearance - g.shelf_right_y;
    if (palm_in_front >= g.min_insertion_depth && plate_over <= 0)
      return {o, std::min(g.insertion_depth, palm_in_front)};
  }
  return {plate_opening_clear_of_right_panel(o, gp.y(), open_width, g), g.insertion_depth};
}

ForeEdges join_split_fore_edge(const ForeEdges& reported, const CycleGeometry& g) {
  if (!(g.split_fore_edge_gap > 0) || !measured(reported.front_width) || !measured(reported.neighbour_offset) ||
      !measured(reported.neighbour_width))
    return reported;
  if (reported.neighbour_offset - reported.front_width >= g.split_fore_edge_gap) return reported;
  return ForeEdges{reported.neighbour_offset + reported.neighbour_width, 0.0, 0.0};
}

bool holds_more_than_the_book(double plate_distance, const ForeEdges& edges, const CycleGeometry& g) {
  return g.more_than_the_book > 0 && measured(edges.front_width) &&
         plate_distance > edges.front_width + g.more_than_the_book;
}

double moves_front_z(double gp_z, const CycleGeometry& g) {
  return std::min(gp_z, g.deep_front_z);
}

double pre_grasp_back_off(double gp_z, const CycleGeometry& g) {
  return g.pre_grasp_distance + (std::isfinite(gp_z) ? gp_z - moves_front_z(gp_z, g) : 0.0);
}

Eigen::Isometry3d pre_grasp_pose(const Eigen::Isometry3d& gp, double gp_z, const CycleGeometry& g) {
  return move_along_own_axes(gp, Eigen::Vector3d(g.grasp_offset_x, g.grasp_offset_y, -pre_grasp_back_off(gp_z, g)));
}

double tcp_height_on_book(const Eigen::Vector3d& gp_grasp, const CycleGeometry& g) {
  return gp_grasp.x() + g.grasp_offset_x;
}

double holder_regrasp_height(double tcp_height, const CycleGeometry& g) {
  return std::max(tcp_height - g.holder_regrasp_lower, std::min(tcp_height, g.holder_regrasp_min_height));
}

double height_held_from_holder(double tcp_height, const CycleGeometry& g) {
  return holder_regrasp_height(tcp_height, g) + g.place_clearance;
}

Eigen::Isometry3d holder_place_pose(const Eigen::Isometry3d& s, double h, const CycleGeometry& g) {
  Eigen::Isometry3d local = Eigen::Isometry3d::Identity();
  local.linear() = g.holder_gripper_axes;
  local.translation() = g.holder_place_tcp + Eigen::Vector3d(0, 0, h + g.place_clearance);
  return s * local;
}

Eigen::Isometry3d holder_pre_place_pose(const Eigen::Isometry3d& s, double h, const CycleGeometry& g) {
  Eigen::Isometry3d p = holder_place_pose(s, h, g);
  p.translation() += s.linear() * g.holder_pre_place_offset;
  return p;
}

std::vector<Eigen::Isometry3d> holder_place_moves(const Eigen::Isometry3d& s, double h, const CycleGeometry& g) {
  const Eigen::Isometry3d place = holder_place_pose(s, h, g);
  if (!(g.holder_place_descent > 0)) return {place};
  Eigen::Isometry3d above = place;
  above.translation() += s.linear().col(2) * g.holder_place_descent;
  return {above, place};
}

std::vector<Eigen::Isometry3d> holder_lift_moves(const Eigen::Isometry3d& s, double h, const CycleGeometry& g) {
  std::vector<Eigen::Isometry3d> moves = holder_place_moves(s, h, g);
  moves.pop_back();  // from the place pose: up first (if a descent is configured), then to the pre-place pose
  moves.push_back(holder_pre_place_pose(s, h, g));
  return moves;
}

double lower_shelf_max_book_height(const CycleGeometry& g) {
  if (g.lower_shelf_gap <= 0) return std::numeric_limits<double>::infinity();
  return g.lower_shelf_gap - 2 * g.lower_book_clearance;
}

double lower_release_width(double book_width, const CycleGeometry& g) {
  return g.lower_release_opening > 0 ? book_width + g.lower_release_opening : 0.0;
}

double next_lower_right_y(double right_y, double book_width, const CycleGeometry& g) {
  return right_y - (book_width + g.lower_gap);
}

OrientedBox lower_shelf_book_box(const Eigen::Isometry3d& f, double right_y, double width, double height, double depth,
                                 const CycleGeometry& g) {
  OrientedBox b;
  b.pose = pose_in_grasp_frame(
      f, Eigen::Vector3d(-g.lower_drop + height / 2, right_y - width / 2, g.lower_front_z + depth / 2));
  b.size = Eigen::Vector3d(height, width, depth);
  return b;
}

Eigen::Isometry3d lower_place_pose(const Eigen::Isometry3d& f, double right_y, double bw, double h,
                                   const CycleGeometry& g) {
  // The closed plates centre the book on the TCP: its right cover is BW/2 right of the TCP.
  return pose_in_grasp_frame(
      f, Eigen::Vector3d(-g.lower_drop + h + g.place_clearance, right_y - bw / 2, g.lower_front_z + g.insertion_depth));
}

Eigen::Isometry3d lower_pre_place_pose(const Eigen::Isometry3d& f, double right_y, double bw, double h,
                                       double held_box_height, const CycleGeometry& g) {
  Eigen::Isometry3d p = lower_place_pose(f, right_y, bw, h, g);
  Eigen::Vector3d offset = g.lower_pre_place_offset;
  if (g.lower_shelf_gap > 0) {
    // TCP height over the place pose that centres the box: box bottom = TCP + top_above - H.
    const double place_x = -g.lower_drop + h + g.place_clearance;
    const double centred_x =
        -g.lower_drop + (g.lower_shelf_gap - held_box_height) / 2 + held_box_height - g.held_top_above_tcp;
    offset.x() = std::max(offset.x(), centred_x - place_x);
  }
  p.translation() += f.linear() * offset;
  return p;
}

}  // namespace bookgrasp
