#include "services/bws_detector/baseline_segmentation.h"

#include <cmath>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "common/config.h"

namespace bookgrasp::bws {

JumpComponentsParams JumpComponentsParams::from_config(const Config& c) {
  JumpComponentsParams p;
  p.max_jump = c.get_double("max_jump", 0.0, 1e9);
  p.min_region_px = c.get_int("min_region_px", 1, 100000000);
  return p;
}

SegmentationResult segment_jump_components(const cv::Mat& image, const cv::Mat& points,
                                           const JumpComponentsParams& p) {
  if (image.type() != CV_32F || image.empty()) throw std::invalid_argument("segment_jump_components: image must be CV_32F");
  if (!points.empty() && (points.type() != CV_32FC3 || points.size() != image.size()))
    throw std::invalid_argument("segment_jump_components: points must be empty or CV_32FC3 of the image's size");
  const int W = image.cols, H = image.rows;
  std::vector<int> parent(size_t(W) * size_t(H));
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int a) {
    while (parent[size_t(a)] != a) {
      parent[size_t(a)] = parent[size_t(parent[size_t(a)])];
      a = parent[size_t(a)];
    }
    return a;
  };
  auto unite = [&](int a, int b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (b < a) std::swap(a, b);
    parent[size_t(b)] = a;
  };
  const float jump = float(p.max_jump);
  auto ok = [](float v) { return std::isfinite(v) && v > 0.f; };
  for (int y = 0; y < H; ++y) {
    const float* r = image.ptr<float>(y);
    const float* ru = y > 0 ? image.ptr<float>(y - 1) : nullptr;
    for (int x = 0; x < W; ++x) {
      if (!ok(r[x])) continue;
      if (x > 0 && ok(r[x - 1]) && std::fabs(r[x] - r[x - 1]) <= jump) unite(y * W + x, y * W + x - 1);
      if (ru && ok(ru[x]) && std::fabs(r[x] - ru[x]) <= jump) unite(y * W + x, (y - 1) * W + x);
    }
  }
  cv::Mat labels(image.size(), CV_32S);
  for (int y = 0; y < H; ++y) {
    const float* r = image.ptr<float>(y);
    int* l = labels.ptr<int>(y);
    for (int x = 0; x < W; ++x) l[x] = ok(r[x]) ? find(y * W + x) + 1 : 0;
  }
  return describe_regions(labels, points.empty() ? image_space_points(image) : points, p.min_region_px);
}

}  // namespace bookgrasp::bws
