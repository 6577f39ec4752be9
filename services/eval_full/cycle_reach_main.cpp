/// @file
/// bookgrasp_cycle_reach: for N seeded scenes, whether the arm can reach every pose of the first
/// book's library cycle, or of every book's (--all-books) (cycle_reach.h), from the scene's truth and the coordinator's
/// geometry, in milliseconds per scene instead of minutes of composed simulation. Prints one line per scene and the
/// unreachable count per stage; use it to try a geometry (scene file, URDF, coordinator keys) before running
/// bookgrasp_eval_full.

#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "common/config.h"
#include "services/eval_full/cycle_reach.h"

namespace {

void usage(std::ostream& os) {
  os << "usage: bookgrasp_cycle_reach --scenes N --seed S [options]\n"
        "  --scene FILE        scene YAML (default config/scenes/default.yaml)\n"
        "  --coordinator FILE  coordinator YAML (default config/services/coordinator.yaml)\n"
        "  --urdf FILE         robot description (default: the scene's robot.urdf)\n"
        "  --set KEY=VALUE     override a coordinator key (dotted, e.g. geometry.grasp.extract_retreat_m=0.31)\n"
        "  --planner-ik FILE   the IK settings of a planner YAML (ik:) instead of 24 restarts from defaults\n"
        "  --all-books         every book of the upper shelf, each as if the books right of it had gone before\n"
        "  --verbose           every stage of every scene with the elbow bend it needs\n"
        "  --source-dir DIR    project tree (default: the one this tool was built from)\n";
}

/// Sets `dotted` in `root` to `value` (parsed as YAML); throws on a key that does not exist.
void set_dotted(YAML::Node root, const std::string& dotted, const std::string& value) {
  std::vector<std::string> parts;
  for (size_t s = 0, e; s <= dotted.size(); s = e + 1) {
    e = dotted.find('.', s);
    if (e == std::string::npos) e = dotted.size();
    parts.push_back(dotted.substr(s, e - s));
  }
  std::vector<YAML::Node> chain{root};
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    if (!chain.back()[parts[i]]) throw std::runtime_error("--set: no key '" + dotted + "' in the coordinator YAML");
    chain.push_back(chain.back()[parts[i]]);
  }
  if (!chain.back()[parts.back()]) throw std::runtime_error("--set: no key '" + dotted + "' in the coordinator YAML");
  chain.back()[parts.back()] = YAML::Load(value);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace bookgrasp;
  int scenes = -1;
  long long seed = -1;
  bool verbose = false, all_books = false;
  std::string source_dir = BOOKGRASP_SOURCE_DIR, scene_file, coord_file, urdf, planner_ik;
  std::vector<std::string> sets;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      auto value = [&]() -> std::string {
        if (i + 1 >= argc) throw std::runtime_error("missing value after " + a);
        return argv[++i];
      };
      if (a == "--scenes")
        scenes = std::stoi(value());
      else if (a == "--seed")
        seed = std::stoll(value());
      else if (a == "--scene")
        scene_file = value();
      else if (a == "--coordinator")
        coord_file = value();
      else if (a == "--urdf")
        urdf = value();
      else if (a == "--set")
        sets.push_back(value());
      else if (a == "--planner-ik")
        planner_ik = value();
      else if (a == "--verbose")
        verbose = true;
      else if (a == "--all-books")
        all_books = true;
      else if (a == "--source-dir")
        source_dir = value();
      else if (a == "--help" || a == "-h") {
        usage(std::cout);
        return 0;
      } else
        throw std::runtime_error("unknown argument " + a);
    }
    if (scenes < 1 || seed < 0) throw std::runtime_error("--scenes N (>= 1) and --seed S (>= 0) are required");
    if (scene_file.empty()) scene_file = source_dir + "/config/scenes/default.yaml";
    if (coord_file.empty()) coord_file = source_dir + "/config/services/coordinator.yaml";

    YAML::Node coord = YAML::LoadFile(coord_file);
    for (const std::string& s : sets) {
      const auto eq = s.find('=');
      if (eq == std::string::npos) throw std::runtime_error("--set '" + s + "' is not KEY=VALUE");
      set_dotted(coord, s.substr(0, eq), s.substr(eq + 1));
    }
    const Config cfg = Config::from_string(YAML::Dump(coord), coord_file);
    const CycleGeometry g = CycleGeometry::from_config(cfg.child("geometry"));
    const std::vector<double> park = cfg.get_vector("park_joints_deg", 7);

    std::map<std::string, int> unreachable;
    std::vector<std::string> order;
    int all_ok = 0, books = 0;
    for (int k = 0; k < scenes; ++k) {
      const uint64_t s = static_cast<uint64_t>(seed + k);
      const scene::Scene scene = scene::load_scene(scene_file, s);
      const ArmKinematics kin = ArmKinematics::from_urdf_file(urdf.empty() ? scene.urdf_path : urdf, "base", "gripper");
      IkParams p;
      p.max_restarts = 24;
      p.seed = s;
      if (!planner_ik.empty()) {
        const Config ik = Config::load_file(planner_ik).child("ik");
        p.max_iterations = ik.get_int("max_iterations", 1, 100000);
        p.max_restarts = ik.get_int("max_restarts", 0, 1000);
        p.position_tolerance_m = ik.get_double("position_tolerance_m", 1e-9, 0.1);
        p.orientation_tolerance_rad = ik.get_double("orientation_tolerance_rad", 1e-9, 1.0);
        p.damping = ik.get_double("damping", 1e-9, 10.0);
        p.max_step_rad = ik.get_double("max_step_rad", 1e-6, 3.2);
        p.nullspace_gain = ik.get_double("nullspace_gain", 0.0, 1.0);
        p.posture_iterations = ik.get_int("posture_iterations", 0, 100000);
        p.orientation_weight_m = ik.get_double("orientation_weight_m", 1e-6, 100.0);
        const std::vector<double> pp = ik.get_vector("preferred_posture", 7);
        p.preferred_posture = Eigen::Map<const Eigen::VectorXd>(pp.data(), 7);
        p.seed = static_cast<uint64_t>(ik.get_int("seed", 0, 1 << 30));
      }
      const InverseKinematics ik(kin, p);
      Eigen::VectorXd q0(7);
      for (int j = 0; j < 7; ++j) q0[j] = park[j] * M_PI / 180.0;
      for (size_t bi = 0; bi < (all_books ? scene.books.size() : 1); ++bi) {
        const std::vector<StageReach> r = cycle_reach(scene, g, ik, q0, bi);
        const scene::Book& b = scene.books[bi];
        ++books;
        std::string failed;
        for (const StageReach& st : r) {
          if (order.size() < r.size()) order.push_back(st.stage);
          if (!st.reachable) {
            ++unreachable[st.stage];
            failed += (failed.empty() ? "" : ",") + st.stage;
          }
        }
        all_ok += failed.empty();
        std::printf("seed %llu book %zu: y %+.3f m (base), height %.3f m: %s\n", static_cast<unsigned long long>(s), bi,
                    b.pose.translation().y(), b.height_m,
                    failed.empty() ? "all reachable" : ("UNREACHABLE " + failed).c_str());
        if (verbose && bi == 0) {
          // The frames the coordinator derives from the markers (AprilTag axes: y down, z into the tag) vs the truth:
          // once a scene.
          const Eigen::Isometry3d flip(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()));
          const Eigen::Isometry3d sup = holder_support_frame(scene.holder_marker.pose * flip, g);
          const Eigen::Isometry3d grf = cart_grasp_frame(scene.cart_marker.pose * flip, g);
          const Eigen::Isometry3d gt = true_grasp_frame(scene);
          std::printf("    holder support from its marker - truth: (%+.4f %+.4f %+.4f) m, %.4f rad\n",
                      (sup.translation() - scene.holder_support_pose.translation()).x(),
                      (sup.translation() - scene.holder_support_pose.translation()).y(),
                      (sup.translation() - scene.holder_support_pose.translation()).z(),
                      Eigen::AngleAxisd(sup.linear().transpose() * scene.holder_support_pose.linear()).angle());
          std::printf("    grasp frame from the cart marker - truth: (%+.4f %+.4f %+.4f) m, %.4f rad\n",
                      (grf.translation() - gt.translation()).x(), (grf.translation() - gt.translation()).y(),
                      (grf.translation() - gt.translation()).z(),
                      Eigen::AngleAxisd(grf.linear().transpose() * gt.linear()).angle());
        }
        if (verbose)
          for (const StageReach& st : r)
            std::printf("    %-17s tcp (%+.3f %+.3f %+.3f)  elbow needs %6.1f deg  %s\n", st.stage.c_str(),
                        st.tcp.translation().x(), st.tcp.translation().y(), st.tcp.translation().z(),
                        st.elbow_needed_rad * 180.0 / M_PI, st.reachable ? "ok" : st.reason.c_str());
      }
    }
    if (all_books)
      std::printf("\n%d of %d books (%d scenes): every stage of the book's cycle reachable\n", all_ok, books, scenes);
    else
      std::printf("\n%d of %d scenes: every stage of the first book's cycle reachable\n", all_ok, scenes);
    for (const std::string& st : order) std::printf("  %-17s unreachable in %d\n", st.c_str(), unreachable[st]);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "bookgrasp_cycle_reach: " << e.what() << "\n";
    usage(std::cerr);
    return 2;
  }
}
