// Tests of the scene generator (common/scene/scene.h) against geometric facts.
#include "common/scene/scene.h"

#include <array>
#include <cmath>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

using namespace bookgrasp;
using namespace bookgrasp::scene;

namespace {
const std::string kScene = std::string(BOOKGRASP_SOURCE_DIR) + "/config/scenes/default.yaml";

std::string read_file(const std::string& p) {
  std::ifstream f(p);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

// Independent 2-D separation test (y, z) of two convex quads: true if they overlap.
bool quads_overlap(const std::vector<Eigen::Vector2d>& a, const std::vector<Eigen::Vector2d>& b) {
  for (const auto* p : {&a, &b})
    for (size_t i = 0; i < p->size(); ++i) {
      const Eigen::Vector2d e = (*p)[(i + 1) % p->size()] - (*p)[i];
      const Eigen::Vector2d n(-e.y(), e.x());
      double amin = 1e9, amax = -1e9, bmin = 1e9, bmax = -1e9;
      for (const auto& q : a) amin = std::min(amin, n.dot(q)), amax = std::max(amax, n.dot(q));
      for (const auto& q : b) bmin = std::min(bmin, n.dot(q)), bmax = std::max(bmax, n.dot(q));
      if (amax <= bmin + 1e-12 || bmax <= amin + 1e-12) return false;
    }
  return true;
}

// Front-face corners of a book as a quad in (y, z), from its pose and size.
std::vector<Eigen::Vector2d> front_quad(const Book& b) {
  std::vector<Eigen::Vector2d> q;
  for (auto [y, z] : {std::pair{-1, -1}, {1, -1}, {1, 1}, {-1, 1}}) {
    const Eigen::Vector3d p = b.pose * Eigen::Vector3d(-b.depth_m / 2, y * b.width_m / 2, z * b.height_m / 2);
    q.emplace_back(p.y(), p.z());
  }
  return q;
}
}  // namespace

TEST(Scene, SameFileAndSeedGiveTheSameScene) {
  const Scene a = load_scene(kScene, 42), b = load_scene(kScene, 42);
  ASSERT_EQ(a.books.size(), b.books.size());
  for (size_t i = 0; i < a.books.size(); ++i) {
    EXPECT_EQ(a.books[i].width_m, b.books[i].width_m);
    EXPECT_EQ(a.books[i].height_m, b.books[i].height_m);
    EXPECT_EQ(a.books[i].depth_m, b.books[i].depth_m);
    EXPECT_TRUE(a.books[i].pose.matrix() == b.books[i].pose.matrix());
    EXPECT_TRUE(a.books[i].cover_rgb == b.books[i].cover_rgb);
    EXPECT_EQ(a.books[i].texture_seed, b.books[i].texture_seed);
    EXPECT_EQ(a.books[i].stamps.size(), b.books[i].stamps.size());
  }
  EXPECT_TRUE(a.lighting.direction == b.lighting.direction);
  EXPECT_EQ(a.lighting.intensity, b.lighting.intensity);
  EXPECT_EQ(a.stereo_left.exposure, b.stereo_left.exposure);
}

TEST(Scene, DifferentSeedsGiveDifferentBooks) {
  const Scene a = load_scene(kScene, 1);
  for (uint64_t seed = 2; seed < 6; ++seed) {
    const Scene b = load_scene(kScene, seed);
    bool differ = a.books.size() != b.books.size();
    for (size_t i = 0; !differ && i < a.books.size(); ++i) differ = a.books[i].width_m != b.books[i].width_m;
    EXPECT_TRUE(differ) << "seed " << seed;
  }
}

TEST(Scene, BooksRespectTheRangesAndAlternate) {
  for (uint64_t seed = 0; seed < 30; ++seed) {
    const Scene s = load_scene(kScene, seed);
    ASSERT_GE(s.books.size(), 2u) << "seed " << seed;
    for (size_t i = 0; i < s.books.size(); ++i) {
      const Book& b = s.books[i];
      EXPECT_GE(b.width_m, 0.010);
      EXPECT_LE(b.width_m, 0.035);
      if (b.portrait) {
        EXPECT_GE(b.height_m, 0.20);
        EXPECT_LE(b.height_m, 0.30);
        EXPECT_LT(b.depth_m, b.height_m);
      } else {
        EXPECT_GE(b.height_m, 0.14);
        EXPECT_LE(b.height_m, 0.19);
        EXPECT_GT(b.depth_m, b.height_m);
      }
      EXPECT_LE(std::abs(b.lean_rad), 3.0 * M_PI / 180.0 + 1e-12);
      if (i > 0) {
        EXPECT_NE(b.portrait, s.books[i - 1].portrait) << "seed " << seed << " book " << i;
      }
      // Fore-edge faces the robot: the body x axis (into the shelf) is base +x.
      EXPECT_NEAR((b.pose.linear() * Eigen::Vector3d::UnitX()).x(), 1.0, 1e-9);
    }
  }
}

TEST(Scene, BooksStandOnTheShelfWithoutInterpenetrating) {
  for (uint64_t seed = 0; seed < 30; ++seed) {
    const Scene s = load_scene(kScene, seed);
    const double shelf_z = s.upper_shelf_z();
    const double right_end = s.cart_pose.translation().y() - s.shelf_width_m / 2;
    const double left_end = s.cart_pose.translation().y() + s.shelf_width_m / 2;
    const double front = s.cart_pose.translation().x(), back = front + s.shelf_depth_m;
    for (size_t i = 0; i < s.books.size(); ++i) {
      const auto c = book_corners(s.books[i].pose, s.books[i].width_m, s.books[i].height_m, s.books[i].depth_m);
      double zmin = 1e9;
      for (const auto& p : c) {
        zmin = std::min(zmin, p.z());
        EXPECT_GE(p.y(), right_end - 1e-9);
        EXPECT_LE(p.y(), left_end + 1e-9);
        EXPECT_GE(p.x(), front - 1e-9);
        EXPECT_LE(p.x(), back - 0.001);  // clear of the stripe on the rear board
      }
      EXPECT_NEAR(zmin, shelf_z, 1e-9) << "seed " << seed << " book " << i << " does not rest on the shelf";
      for (size_t j = i + 1; j < s.books.size(); ++j)
        EXPECT_FALSE(quads_overlap(front_quad(s.books[i]), front_quad(s.books[j])))
            << "seed " << seed << " books " << i << " and " << j;
    }
  }
}

// pushed_fronts.yaml (the BwS stress set, docs/BWS.md): fore-edges 0-14 cm behind the shelf's front edge, many of
// them deeper than far_cart.yaml's 2 cm, every book still on the shelf and clear of the rear board.
TEST(Scene, PushedFrontsStandUpTo14CmDeep) {
  const std::string file = std::string(BOOKGRASP_SOURCE_DIR) + "/config/scenes/pushed_fronts.yaml";
  int books = 0, deeper_than_2cm = 0;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    const Scene s = load_scene(file, seed);
    const double front = s.cart_pose.translation().x(), back = front + s.shelf_depth_m;
    for (const Book& b : s.books) {
      double fore_edge = 1e9, rear = -1e9;
      for (const auto& p : book_corners(b.pose, b.width_m, b.height_m, b.depth_m)) {
        fore_edge = std::min(fore_edge, p.x());
        rear = std::max(rear, p.x());
      }
      EXPECT_GE(fore_edge - front, -1e-9) << "seed " << seed;
      EXPECT_LE(fore_edge - front, 0.14 + 0.01) << "seed " << seed;  // + the lean's few millimetres
      EXPECT_LE(rear, back - 0.001) << "seed " << seed;
      ++books;
      if (fore_edge - front > 0.02 + 0.005) ++deeper_than_2cm;
    }
  }
  EXPECT_GT(deeper_than_2cm, books / 2) << deeper_than_2cm << " of " << books;
}

TEST(Scene, RightmostBookIsAtARandomPosition) {
  double ymin = 1e9, ymax = -1e9;
  for (uint64_t seed = 0; seed < 30; ++seed) {
    const Scene s = load_scene(kScene, seed);
    const auto c = book_corners(s.books[0].pose, s.books[0].width_m, s.books[0].height_m, s.books[0].depth_m);
    double y = 1e9;
    for (const auto& p : c) y = std::min(y, p.y());
    // Book 0 is the right-most: no other book has a corner further right.
    for (size_t i = 1; i < s.books.size(); ++i)
      for (const auto& p : book_corners(s.books[i].pose, s.books[i].width_m, s.books[i].height_m, s.books[i].depth_m))
        EXPECT_GT(p.y(), y);
    ymin = std::min(ymin, y);
    ymax = std::max(ymax, y);
  }
  EXPECT_GT(ymax - ymin, 0.15) << "right-most position hardly varies over 30 seeds";
}

TEST(Scene, P1IsTheUpperRightFrontCorner) {
  const Scene s = load_scene(kScene, 3);
  const Book& b = s.books[0];
  const auto c = book_corners(b.pose, b.width_m, b.height_m, b.depth_m);
  const Eigen::Vector3d p1 = c[kP1CornerIndex];
  // Front (towards the robot = smallest x, the four front corners share it), right (-y), up (+z).
  for (int i = 0; i < 8; ++i) {
    if (i == kP1CornerIndex) continue;
    const bool front = (i & 1) == 0;
    EXPECT_LE(p1.x(), c[i].x() + 1e-9);
    if (front && (i & 4)) {
      EXPECT_LT(p1.y(), c[i].y());  // the other top front corner is to the left
    }
    if (front && !(i & 2)) {
      EXPECT_GT(p1.z(), c[i].z());  // the other right front corner is lower
    }
  }
}

TEST(Scene, StripeEndIsAtTheRightmostBooksRightSide) {
  const Scene s = load_scene(kScene, 5);
  const Book& b = s.books[0];
  const Eigen::Vector3d e = stripe_end(s, b.pose, b.width_m, b.height_m, b.depth_m);
  EXPECT_NEAR(e.x(), s.cart_pose.translation().x() + s.shelf_depth_m, 1e-9);
  EXPECT_NEAR(e.z(), s.upper_shelf_z() + s.stripe_height_m, 1e-9);
  // Independent: the right front edge's y at the stripe height (lean about x, small).
  const Eigen::Vector3d bottom = b.pose * Eigen::Vector3d(-b.depth_m / 2, -b.width_m / 2, -b.height_m / 2);
  const Eigen::Vector3d dir = b.pose.linear() * Eigen::Vector3d::UnitZ();
  const double t = (e.z() - bottom.z()) / dir.z();
  EXPECT_NEAR(e.y(), bottom.y() + t * dir.y(), 1e-9);
}

TEST(Scene, CamerasFollowTheConfiguration) {
  const Scene s = load_scene(kScene, 1);
  // Optical z points at look_at; right camera 12 cm along the left camera's x; y points down-ish.
  const Eigen::Vector3d look(0.70, -0.12, 0.10);
  const Eigen::Vector3d z = s.stereo_left.pose.linear().col(2);
  EXPECT_NEAR(z.dot((look - s.stereo_left.pose.translation()).normalized()), 1.0, 1e-9);
  const Eigen::Vector3d d = s.stereo_right.pose.translation() - s.stereo_left.pose.translation();
  EXPECT_NEAR(d.norm(), 0.12, 1e-12);
  EXPECT_NEAR(d.normalized().dot(s.stereo_left.pose.linear().col(0)), 1.0, 1e-12);
  EXPECT_LT(s.stereo_left.pose.linear().col(1).z(), 0.0);
  EXPECT_EQ(s.stereo_left.width, 640);
  EXPECT_EQ(s.stereo_left.height, 480);
  const double dist = (look - s.stereo_left.pose.translation()).norm();
  EXPECT_GT(dist, 1.3);
  EXPECT_LT(dist, 1.7);
}

TEST(Scene, TheHoldersLedgeReachesBeyondTheBackPlatesRightEnd) {
  std::string yaml = read_file(kScene);
  const auto pos = yaml.find("ledge_extension_right_m: ");
  ASSERT_NE(pos, std::string::npos);
  const auto end = yaml.find_first_of(" \n", pos + 25);
  for (const double ext : {0.0, 0.1}) {
    std::string y = yaml;
    y.replace(pos, end - pos, "ledge_extension_right_m: " + std::to_string(ext));
    const Scene s = generate_scene(Config::from_string(y, "test.yaml"), 1, std::string(BOOKGRASP_SOURCE_DIR) + "/config/scenes");
    // Right ends (-y of the holder frame) of the back plate and the ledge, and the ledge's left end.
    const auto y_range = [&](const std::string& name) {
      for (const StaticBox& b : s.boxes)
        if (b.name == name) {
          // The box's corners in the holder frame (book_corners: x = depth, y = width, z = height).
          const Eigen::Vector3d size = 2 * b.half_size;
          double lo = 1e9, hi = -1e9;
          for (const Eigen::Vector3d& c : book_corners(s.holder_pose.inverse() * b.pose, size.y(), size.z(), size.x())) {
            lo = std::min(lo, c.y());
            hi = std::max(hi, c.y());
          }
          return std::pair<double, double>{lo, hi};
        }
      ADD_FAILURE() << "no box " << name;
      return std::pair<double, double>{0, 0};
    };
    const auto back = y_range("holder_back"), ledge = y_range("holder_ledge"), lip = y_range("holder_lip");
    EXPECT_NEAR(back.first, -0.20, 1e-9);  // base_size_m y 0.40
    EXPECT_NEAR(ledge.first, -0.20 - ext, 1e-9) << ext;
    EXPECT_NEAR(lip.first, -0.20 - ext, 1e-9) << ext;
    EXPECT_NEAR(ledge.second, back.second, 1e-9);
  }
}

TEST(Scene, ANegativeLedgeExtensionNamesTheKey) {
  std::string yaml = read_file(kScene);
  const auto pos = yaml.find("ledge_extension_right_m: 0.10");
  ASSERT_NE(pos, std::string::npos);
  yaml.replace(pos, 29, "ledge_extension_right_m: -0.1");
  try {
    generate_scene(Config::from_string(yaml, "test.yaml"), 1, std::string(BOOKGRASP_SOURCE_DIR) + "/config/scenes");
    FAIL() << "no error for a negative ledge extension";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("holder.ledge_extension_right_m"), std::string::npos) << e.what();
  }
}

TEST(Scene, BadGripperContactKeysAreNamed) {
  for (const auto& [from, to, key] : std::vector<std::array<std::string, 3>>{
           {"finger_solref: [0.01, 1.0]", "finger_solref: [0.003, 1.0]", "physics.finger_solref"},
           {"gripper_coupling_solref: [0.004, 1.0]", "gripper_coupling_solref: [0.004, 0.0]",
            "physics.gripper_coupling_solref"},
           {"finger_solimp: [0.95, 0.99, 0.001]", "finger_solimp: [0.95, 0.9, 0.001]", "physics.finger_solimp"},
           {"finger_solimp: [0.95, 0.99, 0.001]", "finger_solimp: [0.95, 0.99]", "finger_solimp"}}) {
    std::string yaml = read_file(kScene);
    const auto pos = yaml.find(from);
    ASSERT_NE(pos, std::string::npos) << from;
    yaml.replace(pos, from.size(), to);
    try {
      generate_scene(Config::from_string(yaml, "test.yaml"), 1, std::string(BOOKGRASP_SOURCE_DIR) + "/config/scenes");
      ADD_FAILURE() << "no error for " << to;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }
}

TEST(Scene, MissingKeyIsNamed) {
  std::string yaml = read_file(kScene);
  const auto pos = yaml.find("  baseline_m: 0.12");
  ASSERT_NE(pos, std::string::npos);
  yaml.erase(pos, yaml.find('\n', pos) - pos);
  const Config cfg = Config::from_string(yaml, "test.yaml");
  try {
    generate_scene(cfg, 1, std::string(BOOKGRASP_SOURCE_DIR) + "/config/scenes");
    FAIL() << "no error for a missing key";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("cameras.stereo.baseline_m"), std::string::npos) << e.what();
  }
}

TEST(Scene, RngIsReproducibleAndUniform) {
  Rng a(7), b(7);
  double sum = 0;
  for (int i = 0; i < 10000; ++i) {
    const double x = a.uniform01();
    EXPECT_EQ(x, b.uniform01());
    EXPECT_GE(x, 0.0);
    EXPECT_LT(x, 1.0);
    sum += x;
  }
  EXPECT_NEAR(sum / 10000, 0.5, 0.02);
  // std::mt19937_64's 10000th output is fixed by the C++ standard.
  std::mt19937_64 e;
  e.discard(9999);
  EXPECT_EQ(e(), 9981545732273789042ull);
}
