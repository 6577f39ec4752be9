#include "services/eval_segmentation/hoover_comparison.h"

#include <algorithm>
#include <map>
#include <stdexcept>
#include <unordered_map>

namespace bookgrasp::eval_segmentation {

const char* hoover_class_name(HooverClass c) {
  switch (c) {
    case HooverClass::kCorrect:
      return "correct";
    case HooverClass::kOver:
      return "over";
    case HooverClass::kUnder:
      return "under";
    case HooverClass::kMissed:
      return "missed";
    case HooverClass::kNoise:
      return "noise";
  }
  return "?";
}

namespace {
HooverClass class_of(const std::vector<int>& labels, const std::vector<HooverClass>& classes, int label,
                     const char* side) {
  const auto it = std::lower_bound(labels.begin(), labels.end(), label);
  if (it == labels.end() || *it != label)
    throw std::out_of_range(std::string("hoover: no ") + side + " region with label " + std::to_string(label));
  return classes[size_t(it - labels.begin())];
}
}  // namespace

HooverClass HooverResult::gt_class_of(int label) const {
  return class_of(gt_labels, gt_class, label, "ground-truth");
}
HooverClass HooverResult::ms_class_of(int label) const {
  return class_of(ms_labels, ms_class, label, "machine");
}

HooverResult hoover_compare(const cv::Mat& gt, const cv::Mat& ms, double T, int no_region) {
  if (!(T > 0.5 && T <= 1.0))
    throw std::invalid_argument("hoover_compare: tolerance T = " + std::to_string(T) + " is outside (0.5, 1]");
  if ((!gt.empty() && gt.type() != CV_32SC1) || (!ms.empty() && ms.type() != CV_32SC1))
    throw std::invalid_argument("hoover_compare: label images must be CV_32SC1 (int32, one channel)");
  if (gt.size() != ms.size())
    throw std::invalid_argument("hoover_compare: ground truth is " + std::to_string(gt.cols) + "x" +
                                std::to_string(gt.rows) + " but the machine segmentation is " +
                                std::to_string(ms.cols) + "x" + std::to_string(ms.rows));
  HooverResult r;
  r.tolerance = T;

  // Overlap table (sparse): (gt label, ms label) -> pixels, on scored pixels only.
  std::map<std::pair<int, int>, int> overlap;
  std::map<int, int> gt_size, ms_size;
  for (int y = 0; y < gt.rows; ++y) {
    const int* g = gt.ptr<int>(y);
    const int* m = ms.ptr<int>(y);
    for (int x = 0; x < gt.cols; ++x) {
      if (g[x] == no_region) continue;
      ++gt_size[g[x]];
      if (m[x] == no_region) continue;
      ++ms_size[m[x]];
      ++overlap[{g[x], m[x]}];
    }
  }
  for (const auto& [l, n] : gt_size) {
    r.gt_labels.push_back(l);
    r.gt_sizes.push_back(n);
  }
  for (const auto& [l, n] : ms_size) {
    r.ms_labels.push_back(l);
    r.ms_sizes.push_back(n);
  }
  const size_t M = r.gt_labels.size(), N = r.ms_labels.size();
  const auto gi = [&](int l) {
    return size_t(std::lower_bound(r.gt_labels.begin(), r.gt_labels.end(), l) - r.gt_labels.begin());
  };
  const auto mi = [&](int l) {
    return size_t(std::lower_bound(r.ms_labels.begin(), r.ms_labels.end(), l) - r.ms_labels.begin());
  };
  struct Cell {
    size_t m, n;
    double o;
  };
  std::vector<Cell> cells;
  cells.reserve(overlap.size());
  for (const auto& [k, o] : overlap) cells.push_back({gi(k.first), mi(k.second), double(o)});
  const auto Pm = [&](size_t m) { return double(r.gt_sizes[m]); };
  const auto Pn = [&](size_t n) { return double(r.ms_sizes[n]); };

  r.gt_class.assign(M, HooverClass::kMissed);
  r.ms_class.assign(N, HooverClass::kNoise);
  std::vector<char> gt_done(M, 0), ms_done(N, 0);

  // 1. Correct detections (unique partners for T > 0.5).
  for (const Cell& c : cells)
    if (c.o >= T * Pm(c.m) && c.o >= T * Pn(c.n) && !gt_done[c.m] && !ms_done[c.n]) {
      gt_done[c.m] = ms_done[c.n] = 1;
      r.gt_class[c.m] = r.ms_class[c.n] = HooverClass::kCorrect;
      ++r.correct;
    }
  // 2. Over-segmentation: per GT region, the unclassified MS regions lying >= T inside it.
  std::vector<std::vector<size_t>> pieces(M);
  std::vector<double> piece_sum(M, 0.0);
  for (const Cell& c : cells)
    if (!gt_done[c.m] && !ms_done[c.n] && c.o >= T * Pn(c.n)) {
      pieces[c.m].push_back(c.n);
      piece_sum[c.m] += c.o;
    }
  // 3. Under-segmentation: per MS region, the unclassified GT regions lying >= T inside it.
  std::vector<std::vector<size_t>> parts(N);
  std::vector<double> part_sum(N, 0.0);
  for (const Cell& c : cells)
    if (!gt_done[c.m] && !ms_done[c.n] && c.o >= T * Pm(c.m)) {
      parts[c.n].push_back(c.m);
      part_sum[c.n] += c.o;
    }
  for (size_t m = 0; m < M; ++m)
    if (pieces[m].size() >= 2 && piece_sum[m] >= T * Pm(m)) {
      gt_done[m] = 1;
      r.gt_class[m] = HooverClass::kOver;
      for (size_t n : pieces[m]) {
        ms_done[n] = 1;
        r.ms_class[n] = HooverClass::kOver;
      }
      ++r.over;
      r.over_ms_regions += int(pieces[m].size());
    }
  for (size_t n = 0; n < N; ++n) {
    if (parts[n].size() < 2 || part_sum[n] < T * Pn(n)) continue;
    // Cannot meet an over-segmented region (see the file comment); checked to keep one class per region.
    bool clash = ms_done[n];
    for (size_t m : parts[n]) clash = clash || gt_done[m];
    if (clash) continue;
    ms_done[n] = 1;
    r.ms_class[n] = HooverClass::kUnder;
    for (size_t m : parts[n]) {
      gt_done[m] = 1;
      r.gt_class[m] = HooverClass::kUnder;
    }
    ++r.under;
    r.under_gt_regions += int(parts[n].size());
  }
  for (size_t m = 0; m < M; ++m) r.missed += gt_done[m] ? 0 : 1;
  for (size_t n = 0; n < N; ++n) r.noise += ms_done[n] ? 0 : 1;
  return r;
}

void HooverTotals::add(const HooverResult& r) {
  gt_regions += r.num_gt();
  ms_regions += r.num_ms();
  correct += r.correct;
  over += r.over;
  under += r.under;
  under_gt_regions += r.under_gt_regions;
  over_ms_regions += r.over_ms_regions;
  missed += r.missed;
  noise += r.noise;
}

namespace {
double frac(long long a, long long b) {
  return b > 0 ? double(a) / double(b) : 0.0;
}
}  // namespace

double HooverTotals::correct_fraction() const {
  return frac(correct, gt_regions);
}
double HooverTotals::over_fraction() const {
  return frac(over, gt_regions);
}
double HooverTotals::under_fraction() const {
  return frac(under_gt_regions, gt_regions);
}
double HooverTotals::missed_fraction() const {
  return frac(missed, gt_regions);
}
double HooverTotals::noise_fraction() const {
  return frac(noise, ms_regions);
}

}  // namespace bookgrasp::eval_segmentation
