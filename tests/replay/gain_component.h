#pragma once
/// @file
/// Test-only component with one numeric parameter, to check that replay
/// reports what a changed parameter moves: pose_t in, pose_t out with the
/// position multiplied by `gain` and a task_status_t counting messages.

#include "bookgrasp/pose_t.hpp"
#include "bookgrasp/task_status_t.hpp"
#include "common/component.h"
#include "common/config.h"

namespace bookgrasp_test {

/// Scales positions; publishes on `channels.output` and a count on `channels.count`.
class GainComponent : public bookgrasp::Component {
 public:
  explicit GainComponent(const bookgrasp::Config& root)
      : Component("gain", "gain"),
        gain_(root.get_double("gain", -100, 100)),
        out_(root.get<std::string>("channels.output")),
        count_(root.get<std::string>("channels.count")) {
    subscribe(root.get<std::string>("channels.input"), &GainComponent::on_pose);
  }

 private:
  void on_pose(const bookgrasp::pose_t& in) {
    bookgrasp::pose_t out = in;
    for (double& p : out.position) p *= gain_;
    publish(out_, out);
    bookgrasp::task_status_t c{};
    c.utime = in.utime;
    c.books_moved = ++n_;
    c.state = "counted";
    publish(count_, c);
  }
  double gain_;
  std::string out_, count_;
  int n_ = 0;
};

}  // namespace bookgrasp_test
