#include "services/bws_detector/hoover_metric.h"

#include <algorithm>
#include <map>
#include <stdexcept>

namespace bookgrasp::bws {

HooverScore hoover_compare(const cv::Mat& gt, const cv::Mat& ms, double T) {
  if (gt.type() != CV_32S || ms.type() != CV_32S) throw std::invalid_argument("hoover_compare: labels must be CV_32S");
  if (gt.size() != ms.size()) throw std::invalid_argument("hoover_compare: label images differ in size");
  if (!(T > 0.5 && T <= 1.0)) throw std::invalid_argument("hoover_compare: tolerance must be in (0.5, 1]");

  std::map<int, int> gt_index, ms_index;  // label -> dense index (sorted labels: deterministic)
  for (int y = 0; y < gt.rows; ++y) {
    const int* g = gt.ptr<int>(y);
    const int* m = ms.ptr<int>(y);
    for (int x = 0; x < gt.cols; ++x) {
      if (g[x] <= 0) continue;
      gt_index.emplace(g[x], 0);
      if (m[x] > 0) ms_index.emplace(m[x], 0);
    }
  }
  int k = 0;
  for (auto& e : gt_index) e.second = k++;
  k = 0;
  for (auto& e : ms_index) e.second = k++;
  const size_t M = gt_index.size(), N = ms_index.size();
  std::vector<double> Pm(M, 0.0), Pn(N, 0.0);
  std::vector<std::map<size_t, double>> O(M);  // sparse overlap rows
  for (int y = 0; y < gt.rows; ++y) {
    const int* g = gt.ptr<int>(y);
    const int* m = ms.ptr<int>(y);
    for (int x = 0; x < gt.cols; ++x) {
      if (g[x] <= 0) continue;
      const size_t i = size_t(gt_index[g[x]]);
      Pm[i] += 1.0;
      if (m[x] > 0) {
        const size_t j = size_t(ms_index[m[x]]);
        Pn[j] += 1.0;
        O[i][j] += 1.0;
      }
    }
  }
  // Column view of the overlaps.
  std::vector<std::map<size_t, double>> Oc(N);
  for (size_t i = 0; i < M; ++i)
    for (const auto& [j, o] : O[i]) Oc[j][i] = o;

  HooverScore s;
  s.gt_regions = int(M);
  s.machine_regions = int(N);
  std::vector<char> gt_used(M, 0), ms_used(N, 0);
  // Correct detections.
  for (size_t i = 0; i < M; ++i)
    for (const auto& [j, o] : O[i])
      if (!ms_used[j] && o >= T * Pm[i] && o >= T * Pn[j]) {
        gt_used[i] = ms_used[j] = 1;
        ++s.correct;
        break;
      }
  // Over-segmentation.
  for (size_t i = 0; i < M; ++i) {
    if (gt_used[i]) continue;
    std::vector<size_t> parts;
    double sum = 0.0;
    for (const auto& [j, o] : O[i])
      if (!ms_used[j] && o >= T * Pn[j]) {
        parts.push_back(j);
        sum += o;
      }
    if (parts.size() >= 2 && sum >= T * Pm[i]) {
      gt_used[i] = 1;
      for (size_t j : parts) ms_used[j] = 1;
      ++s.over;
    }
  }
  // Under-segmentation.
  for (size_t j = 0; j < N; ++j) {
    if (ms_used[j]) continue;
    std::vector<size_t> parts;
    double sum = 0.0;
    for (const auto& [i, o] : Oc[j])
      if (!gt_used[i] && o >= T * Pm[i]) {
        parts.push_back(i);
        sum += o;
      }
    if (parts.size() >= 2 && sum >= T * Pn[j]) {
      ms_used[j] = 1;
      for (size_t i : parts) gt_used[i] = 1;
      ++s.under;
      s.under_gt_regions += int(parts.size());
    }
  }
  for (size_t i = 0; i < M; ++i) s.missed += gt_used[i] ? 0 : 1;
  for (size_t j = 0; j < N; ++j) s.noise += ms_used[j] ? 0 : 1;
  return s;
}

}  // namespace bookgrasp::bws
