#include "services/marker_detector/tag_detector.h"

#include <algorithm>
#include <stdexcept>

#include <apriltag/apriltag.h>
#include <apriltag/tag16h5.h>
#include <apriltag/tag25h9.h>
#include <apriltag/tag36h11.h>

namespace bookgrasp {

TagDetectorParams TagDetectorParams::from_config(const Config& cfg) {
  TagDetectorParams p;
  p.family = cfg.get_choice("family", {"tag36h11", "tag25h9", "tag16h5"});
  p.quad_decimate = cfg.get_double("quad_decimate", 1.0, 8.0);
  p.quad_sigma = cfg.get_double("quad_sigma", 0.0, 5.0);
  p.refine_edges = cfg.get<bool>("refine_edges");
  p.decode_sharpening = cfg.get_double("decode_sharpening", 0.0, 2.0);
  p.threads = cfg.get_int("threads", 1, 16);
  p.max_hamming = cfg.get_int("max_hamming", 0, 2);
  p.min_decision_margin = cfg.get_double("min_decision_margin", 0.0, 255.0);
  return p;
}

struct TagDetector::Impl {
  apriltag_family_t* family = nullptr;
  apriltag_detector_t* detector = nullptr;
  void (*destroy_family)(apriltag_family_t*) = nullptr;

  ~Impl() {
    if (detector) apriltag_detector_destroy(detector);
    if (family && destroy_family) destroy_family(family);
  }
};

TagDetector::TagDetector(const TagDetectorParams& params) : params_(params), impl_(std::make_unique<Impl>()) {
  if (params.quad_decimate < 1.0) {
    throw std::invalid_argument("quad_decimate must be >= 1 (got " + std::to_string(params.quad_decimate) + ")");
  }
  if (params.threads < 1) throw std::invalid_argument("threads must be >= 1");
  if (params.max_hamming < 0 || params.max_hamming > 2) {
    throw std::invalid_argument("max_hamming must be 0, 1 or 2 (AprilTag 3 corrects at most 2 bits)");
  }
  if (params.family == "tag36h11") {
    impl_->family = tag36h11_create();
    impl_->destroy_family = tag36h11_destroy;
  } else if (params.family == "tag25h9") {
    impl_->family = tag25h9_create();
    impl_->destroy_family = tag25h9_destroy;
  } else if (params.family == "tag16h5") {
    impl_->family = tag16h5_create();
    impl_->destroy_family = tag16h5_destroy;
  } else {
    throw std::invalid_argument("unknown tag family '" + params.family + "' (use tag36h11, tag25h9 or tag16h5)");
  }
  impl_->detector = apriltag_detector_create();
  apriltag_detector_add_family_bits(impl_->detector, impl_->family, params.max_hamming);
  impl_->detector->quad_decimate = static_cast<float>(params.quad_decimate);
  impl_->detector->quad_sigma = static_cast<float>(params.quad_sigma);
  impl_->detector->refine_edges = params.refine_edges;
  impl_->detector->decode_sharpening = params.decode_sharpening;
  impl_->detector->nthreads = params.threads;
  impl_->detector->debug = false;
}

TagDetector::~TagDetector() = default;
TagDetector::TagDetector(TagDetector&&) noexcept = default;
TagDetector& TagDetector::operator=(TagDetector&&) noexcept = default;

std::vector<TagDetection> TagDetector::detect(const cv::Mat& gray) {
  if (gray.empty() || gray.type() != CV_8UC1) {
    throw std::invalid_argument("TagDetector::detect needs a non-empty CV_8UC1 image (convert colour to grey first)");
  }
  const cv::Mat img = gray.isContinuous() ? gray : gray.clone();
  image_u8_t im{img.cols, img.rows, static_cast<int32_t>(img.step[0]), const_cast<uint8_t*>(img.ptr<uint8_t>(0))};
  zarray_t* found = apriltag_detector_detect(impl_->detector, &im);
  std::vector<TagDetection> out;
  out.reserve(static_cast<size_t>(zarray_size(found)));
  for (int i = 0; i < zarray_size(found); ++i) {
    apriltag_detection_t* det = nullptr;
    zarray_get(found, i, &det);
    if (det->hamming > params_.max_hamming || det->decision_margin < params_.min_decision_margin) continue;
    TagDetection d;
    d.family = det->family->name;
    d.id = det->id;
    d.hamming = det->hamming;
    d.decision_margin = det->decision_margin;
    for (int k = 0; k < 4; ++k) d.corners[static_cast<size_t>(k)] = cv::Point2d(det->p[k][0], det->p[k][1]);
    d.center = cv::Point2d(det->c[0], det->c[1]);
    out.push_back(d);
  }
  apriltag_detections_destroy(found);
  sort_tag_detections(&out);
  return out;
}

void sort_tag_detections(std::vector<TagDetection>* tags) {
  std::sort(tags->begin(), tags->end(), [](const TagDetection& a, const TagDetection& b) {
    if (a.id != b.id) return a.id < b.id;
    if (a.center.x != b.center.x) return a.center.x < b.center.x;
    return a.center.y < b.center.y;
  });
}

}  // namespace bookgrasp
