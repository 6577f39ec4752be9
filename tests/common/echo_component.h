#pragma once
/// @file
/// A component for testing the runtime (tests only): republishes task_status_t
/// from its input channel to its output channel, counts image_t messages and
/// can be told to throw, to exercise rejection.

#include <string>

#include "bookgrasp/image_t.hpp"
#include "bookgrasp/task_status_t.hpp"
#include "common/component.h"
#include "common/config.h"

namespace bookgrasp_test {

/// Echoes TASK_STATUS-typed messages; a message whose `message` is "throw" makes the handler throw.
class EchoComponent : public bookgrasp::Component {
 public:
  /// Reads `channels.input`, `channels.output`, `channels.images` from `root`.
  explicit EchoComponent(const bookgrasp::Config& root)
      : Component(root.get<std::string>("service.name"), root.get<std::string>("service.implementation")),
        output_(root.get<std::string>("channels.output")) {
    subscribe(root.get<std::string>("channels.input"), &EchoComponent::on_status);
    subscribe(root.get<std::string>("channels.images"), &EchoComponent::on_image);
  }
  /// Images received so far.
  int images() const { return images_; }

 private:
  void on_status(const bookgrasp::task_status_t& msg) {
    if (msg.message == "throw") throw std::runtime_error("asked to throw");
    bookgrasp::task_status_t out = msg;
    out.state = "echo:" + msg.state;
    out.message = implementation();
    publish(output_, out);
  }
  void on_image(const bookgrasp::image_t& img) {
    if (img.size != static_cast<int32_t>(img.data.size())) {
      reject("images", "size field does not match data");
      return;
    }
    ++images_;
  }
  std::string output_;
  int images_ = 0;
};

}  // namespace bookgrasp_test
