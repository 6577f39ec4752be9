#include "services/snapshot/truth_json.h"

#include <cmath>
#include <cstdio>
#include <sstream>

namespace bookgrasp::snapshot {
namespace {

std::string num(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.17g", v);
  return buf;
}

std::string str(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\u%04x", c);
      out += buf;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string vec(const double* v, int n) {
  std::string out = "[";
  for (int i = 0; i < n; ++i) out += (i ? ", " : "") + num(v[i]);
  return out + "]";
}

std::string pose(const pose_t& p) {
  return "{\"utime\": " + std::to_string(p.utime) + ", \"frame\": " + str(p.frame) + ", \"child\": " +
         str(p.child) + ", \"position\": " + vec(p.position, 3) + ", \"orientation_wxyz\": " +
         vec(p.orientation, 4) + "}";
}

}  // namespace

std::string ground_truth_json(const ground_truth_t& t) {
  std::ostringstream o;
  o << "{\n  \"utime\": " << t.utime << ",\n  \"scene\": " << str(t.scene) << ",\n  \"seed\": " << t.seed
    << ",\n  \"cart\": " << pose(t.cart) << ",\n  \"holder\": " << pose(t.holder)
    << ",\n  \"cart_marker\": " << pose(t.cart_marker) << ",\n  \"holder_marker\": " << pose(t.holder_marker)
    << ",\n  \"stripe_end_base\": " << vec(t.stripe_end_base, 3) << ",\n  \"num_books\": " << t.num_books
    << ",\n  \"books\": [";
  for (size_t i = 0; i < t.books.size(); ++i) {
    const book_truth_t& b = t.books[i];
    o << (i ? "," : "") << "\n    {\"utime\": " << b.utime << ", \"id\": " << b.id << ", \"name\": " << str(b.name)
      << ", \"place\": " << str(b.place) << ", \"rightmost\": " << (b.rightmost ? "true" : "false")
      << ", \"portrait\": " << (b.portrait ? "true" : "false") << ",\n     \"width_m\": " << num(b.width_m)
      << ", \"height_m\": " << num(b.height_m) << ", \"depth_m\": " << num(b.depth_m)
      << ",\n     \"corners_base\": [";
    for (int k = 0; k < 8; ++k) o << (k ? ", " : "") << vec(b.corners_base[k], 3);
    o << "],\n     \"p1_base\": " << vec(b.p1_base, 3) << ",\n     \"pose\": " << pose(b.pose) << "}";
  }
  o << "\n  ]\n}\n";
  return o.str();
}

}  // namespace bookgrasp::snapshot
