#include "services/bws_detector/cart_geometry.h"

#include <cmath>
#include <string>
#include <vector>

#include "common/config.h"
#include "common/grasp_frame.h"

namespace bookgrasp::bws {

namespace {
Eigen::Vector3d vec3(const Config& c, const std::string& key) {
  const std::vector<double> v = c.get_vector(key, 3);
  for (double x : v)
    if (!std::isfinite(x) || std::fabs(x) > 10.0)
      throw ConfigError(c.source() + ": " + c.path_of(key) + ": values must be finite metres within +-10");
  return {v[0], v[1], v[2]};
}
}  // namespace

CartGeometry CartGeometry::from_config(const Config& c) {
  CartGeometry g;
  g.marker_in_cart = vec3(c, "marker_in_cart_m");
  g.shelf_min_cart = vec3(c, "upper_shelf_min_m");
  g.shelf_max_cart = vec3(c, "upper_shelf_max_m");
  for (int i = 0; i < 3; ++i)
    if (!(g.shelf_min_cart(i) < g.shelf_max_cart(i)))
      throw ConfigError(c.source() + ": " + c.path_of("upper_shelf_max_m") +
                        ": every coordinate must be above upper_shelf_min_m's");
  g.max_marker_age_s = c.get_double("max_marker_age_s", 0.0, 1e6);
  return g;
}

Eigen::Isometry3d cart_from_marker(const Eigen::Isometry3d& marker_in_base, const CartGeometry& g) {
  Eigen::Isometry3d marker_in_cart = Eigen::Isometry3d::Identity();
  marker_in_cart.linear().col(0) = -Eigen::Vector3d::UnitY();
  marker_in_cart.linear().col(1) = -Eigen::Vector3d::UnitZ();
  marker_in_cart.linear().col(2) = Eigen::Vector3d::UnitX();
  marker_in_cart.translation() = g.marker_in_cart;
  return marker_in_base * marker_in_cart.inverse();
}

ShelfVolume shelf_volume(const Eigen::Isometry3d& cart_in_base, const CartGeometry& g) {
  ShelfVolume v;
  Eigen::Isometry3d centre = Eigen::Isometry3d::Identity();
  centre.translation() = 0.5 * (g.shelf_min_cart + g.shelf_max_cart);
  v.box_in_base = cart_in_base * centre;
  v.half_extent = 0.5 * (g.shelf_max_cart - g.shelf_min_cart);
  return v;
}

Eigen::Isometry3d grasp_frame_of_cart(const Eigen::Isometry3d& cart_in_base) {
  return grasp_frame_in_base(cart_in_base.linear().col(0), cart_in_base.translation());
}

}  // namespace bookgrasp::bws
