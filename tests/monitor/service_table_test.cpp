#include "services/monitor/service_table.h"

#include <gtest/gtest.h>

namespace bookgrasp {
namespace {

service_status_t status(const std::string& name, int pid, int8_t state, double rate) {
  service_status_t s{};
  s.service = name;
  s.implementation = "impl";
  s.pid = pid;
  s.state = state;
  channel_stats_t c{};
  c.channel = "STEREO_IMAGES";
  c.rate_hz = rate;
  c.age_s = 0.2;
  s.inputs.push_back(c);
  s.num_inputs = 1;
  return s;
}

TEST(ServiceTable, TracksServicesRestartsAndStaleness) {
  ServiceTable t;
  t.update(status("bws_detector", 100, service_status_t::RUNNING, 10.0), 1000000);
  t.update(status("marker_detector", 200, service_status_t::DEGRADED, 9.5), 1000000);
  EXPECT_EQ(t.missing({"bws_detector", "planner"}), std::vector<std::string>{"planner"});
  t.update(status("bws_detector", 101, service_status_t::RUNNING, 10.0), 2000000);  // restarted
  EXPECT_EQ(t.rows().at("bws_detector").restarts, 1);
  EXPECT_EQ(t.rows().at("marker_detector").restarts, 0);
  const std::string table = t.render(2500000, 3.0);
  EXPECT_NE(table.find("DEGRADED"), std::string::npos) << table;
  EXPECT_NE(table.find("STEREO_IMAGES 10.0Hz"), std::string::npos) << table;
  // 10 s later nothing new: both are stale.
  const std::string later = t.render(12500000, 3.0);
  EXPECT_EQ(later.find("RUNNING"), std::string::npos) << later;
  EXPECT_NE(later.find("STALE"), std::string::npos) << later;
}

TEST(ServiceTable, EmptyTableSaysSo) {
  EXPECT_NE(ServiceTable().render(0).find("no SERVICE_STATUS"), std::string::npos);
}

}  // namespace
}  // namespace bookgrasp
