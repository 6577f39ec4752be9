// Developer tool: renders a synthetic shelf scene (seed argv[1]), runs disparity (exact or StereoBM)
// and GoD, and writes PNGs of every stage into argv[2] for inspection.
#include <cstdio>
#include <cstdlib>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "services/bws_detector/disparity.h"
#include "services/bws_detector/god_segmentation.h"
#include "synthetic_shelf.h"

using namespace bookgrasp::bws;

static cv::Mat colour_labels(const cv::Mat& labels) {
  cv::Mat out(labels.size(), CV_8UC3, cv::Scalar(0, 0, 0));
  for (int y = 0; y < labels.rows; ++y)
    for (int x = 0; x < labels.cols; ++x) {
      const int l = labels.at<int>(y, x);
      if (l <= 0) continue;
      const unsigned h = unsigned(l) * 2654435761u;
      out.at<cv::Vec3b>(y, x) = cv::Vec3b(uint8_t(60 + (h & 0xbf)), uint8_t(60 + ((h >> 8) & 0xbf)), uint8_t(60 + ((h >> 16) & 0xbf)));
    }
  return out;
}

int main(int argc, char** argv) {
  const unsigned seed = argc > 1 ? unsigned(std::atoi(argv[1])) : 11;
  const std::string dir = argc > 2 ? argv[2] : ".";
  const bool bm = argc > 3 && std::string(argv[3]) == "bm";
  const test::ShelfScene scene = test::make_shelf_scene(seed);
  const test::RenderOutput L = test::render_boxes(scene.boxes, scene.left, true);
  cv::Mat disp;
  if (bm) {
    const test::RenderOutput R = test::render_boxes(scene.boxes, scene.right, true);
    cv::imwrite(dir + "/left.png", L.intensity);
    cv::imwrite(dir + "/right.png", R.intensity);
    DisparityParams dp;
    if (argc > 4) dp.block_size = std::atoi(argv[4]);
    if (argc > 5 && std::string(argv[5]) == "sgbm") dp.algorithm = StereoAlgorithm::kSemiGlobal;
    disp = compute_disparity(L.intensity, R.intensity, dp);
  } else {
    disp = test::exact_disparity(L.depth, scene.left.fx, scene.baseline_m);
  }
  cv::Mat d8;
  cv::Mat dd = disp.clone();
  cv::patchNaNs(dd, 0);
  dd.convertTo(d8, CV_8U, 255.0 / 64.0);
  cv::imwrite(dir + "/disparity.png", d8);
  GodParams p;
  GodDebug dbg;
  const SegmentationResult r = segment_god(disp, cv::Mat(), p, &dbg);
  cv::Mat dg;
  cv::Mat dgod = dbg.features.dgod.clone();
  cv::patchNaNs(dgod, 0);
  dgod.convertTo(dg, CV_8U, 255.0 / 360.0);
  cv::applyColorMap(dg, dg, cv::COLORMAP_HSV);
  cv::imwrite(dir + "/dgod.png", dg);
  cv::Mat cl;
  dbg.clusters.convertTo(cl, CV_32S);
  cl.setTo(0, dbg.clusters == 255);
  cl += 1;
  cl.setTo(0, dbg.clusters == 255);
  cv::imwrite(dir + "/clusters.png", colour_labels(cl * 7919));
  cv::imwrite(dir + "/initial.png", colour_labels(dbg.initial_labels));
  cv::imwrite(dir + "/regions.png", colour_labels(r.labels));
  cv::imwrite(dir + "/truth.png", colour_labels(L.face_id));
  cv::imwrite(dir + "/intensity.png", L.intensity);
  cv::Mat ib, top, bot, grid;
  cv::cvtColor(L.intensity, ib, cv::COLOR_GRAY2BGR);
  cv::hconcat(ib, colour_labels(L.face_id), top);
  cv::hconcat(dg, colour_labels(r.labels), bot);
  cv::vconcat(top, bot, grid);
  cv::imwrite(dir + "/grid.png", grid);
  std::printf("initial %d merges %d rounds %d regions %zu\n", dbg.initial_count, dbg.merges, dbg.merge_rounds,
              r.regions.size());
  return 0;
}
