#include "services/marker_detector/tag_search.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace bookgrasp {

TagTrackingParams TagTrackingParams::from_config(const Config& cfg) {
  TagTrackingParams p;
  p.enabled = cfg.get<bool>("enabled");
  p.roi_margin = cfg.get_double("roi_margin", 0.1, 10.0);
  p.roi_min_px = cfg.get_int("roi_min_px", 16, 100000);
  p.full_search_period_s = cfg.get_double("full_search_period_s", 0.0, 3600.0);
  return p;
}

namespace {

std::set<int> ids_of(const std::vector<TagDetection>& tags) {
  std::set<int> ids;
  for (const TagDetection& t : tags) ids.insert(t.id);
  return ids;
}

// Merges overlapping rectangles into their bounding rectangles until none overlap.
std::vector<cv::Rect> merge_overlapping(std::vector<cv::Rect> rects) {
  bool merged = true;
  while (merged) {
    merged = false;
    for (size_t i = 0; i < rects.size() && !merged; ++i) {
      for (size_t j = i + 1; j < rects.size(); ++j) {
        if ((rects[i] & rects[j]).area() > 0) {
          rects[i] |= rects[j];
          rects.erase(rects.begin() + static_cast<std::ptrdiff_t>(j));
          merged = true;
          break;
        }
      }
    }
  }
  return rects;
}

}  // namespace

TagSearch::TagSearch(const TagDetectorParams& detector, double fallback_quad_sigma, const TagTrackingParams& tracking,
                     std::set<int> required_ids)
    : detector_(detector), tracking_(tracking), required_ids_(std::move(required_ids)) {
  if (!(tracking.roi_margin > 0) || tracking.roi_min_px < 1 || !(tracking.full_search_period_s >= 0)) {
    throw std::invalid_argument("tracking: roi_margin must be > 0, roi_min_px >= 1 and full_search_period_s >= 0");
  }
  if (fallback_quad_sigma > 0) {
    TagDetectorParams p = detector;
    p.quad_sigma = fallback_quad_sigma;
    fallback_.emplace(p);
  }
}

void TagSearch::reset() {
  previous_.clear();
  last_utime_.reset();
  last_full_utime_.reset();
}

std::vector<TagDetection> TagSearch::search(const cv::Mat& gray, const std::set<int>& wanted, bool* fallback_used) {
  std::vector<TagDetection> found = detector_.detect(gray);
  if (!fallback_) return found;
  std::set<int> missing = wanted;
  for (const TagDetection& d : found) missing.erase(d.id);
  if (missing.empty()) return found;
  *fallback_used = true;
  for (const TagDetection& d : fallback_->detect(gray))
    if (missing.count(d.id)) found.push_back(d);
  return found;
}

std::vector<cv::Rect> TagSearch::regions(const cv::Size& image) const {
  // Align to the detector's threshold tiles (4 px of the decimated image), so a region's pixels are
  // thresholded as in the whole image.
  const int align = 4 * std::max(1, static_cast<int>(std::lround(detector_.params().quad_decimate)));
  std::vector<cv::Rect> rects;
  for (const TagDetection& t : previous_) {
    double x0 = t.corners[0].x, x1 = x0, y0 = t.corners[0].y, y1 = y0;
    for (const cv::Point2d& c : t.corners) {
      x0 = std::min(x0, c.x);
      x1 = std::max(x1, c.x);
      y0 = std::min(y0, c.y);
      y1 = std::max(y1, c.y);
    }
    const double grow = tracking_.roi_margin * std::max(x1 - x0, y1 - y0);
    const double half_min = 0.5 * tracking_.roi_min_px;
    const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
    x0 = std::min(x0 - grow, cx - half_min);
    x1 = std::max(x1 + grow, cx + half_min);
    y0 = std::min(y0 - grow, cy - half_min);
    y1 = std::max(y1 + grow, cy + half_min);
    const int ix0 = std::max(0, static_cast<int>(std::floor(x0)) / align * align);
    const int iy0 = std::max(0, static_cast<int>(std::floor(y0)) / align * align);
    const int ix1 = std::min(image.width, static_cast<int>(std::ceil(x1)) + 1);
    const int iy1 = std::min(image.height, static_cast<int>(std::ceil(y1)) + 1);
    if (ix1 > ix0 && iy1 > iy0) rects.emplace_back(ix0, iy0, ix1 - ix0, iy1 - iy0);
  }
  return merge_overlapping(std::move(rects));
}

TagSearchResult TagSearch::detect(const cv::Mat& gray, int64_t utime) {
  if (gray.empty() || gray.type() != CV_8UC1) {
    throw std::invalid_argument("TagSearch::detect needs a non-empty CV_8UC1 image (convert colour to grey first)");
  }
  if ((last_utime_ && utime < *last_utime_) || gray.size() != last_size_) reset();
  last_utime_ = utime;
  last_size_ = gray.size();

  TagSearchResult result;
  const bool full_due =
      !last_full_utime_ || static_cast<double>(utime - *last_full_utime_) >= tracking_.full_search_period_s * 1e6;
  if (tracking_.enabled && !previous_.empty() && !full_due) {
    const std::set<int> expected = ids_of(previous_);
    std::set<int> wanted;
    for (int id : expected)
      if (required_ids_.count(id)) wanted.insert(id);
    std::vector<TagDetection> found;
    const std::vector<cv::Rect> rects = regions(gray.size());
    for (const cv::Rect& r : rects) {
      for (TagDetection d : search(gray(r), wanted, &result.fallback_used)) {
        for (cv::Point2d& c : d.corners) c += cv::Point2d(r.x, r.y);
        d.center += cv::Point2d(r.x, r.y);
        found.push_back(d);
      }
    }
    const std::set<int> found_ids = ids_of(found);
    if (std::includes(found_ids.begin(), found_ids.end(), expected.begin(), expected.end())) {
      sort_tag_detections(&found);
      result.tags = std::move(found);
      result.mode = TagSearchMode::kRegions;
      result.regions = static_cast<int>(rects.size());
      previous_ = result.tags;
      return result;
    }
  }
  result = TagSearchResult{};
  result.tags = search(gray, required_ids_, &result.fallback_used);
  sort_tag_detections(&result.tags);
  result.mode = TagSearchMode::kFull;
  last_full_utime_ = utime;
  previous_ = result.tags;
  return result;
}

}  // namespace bookgrasp
