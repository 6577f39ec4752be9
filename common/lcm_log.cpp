#include "common/lcm_log.h"

#include <fstream>
#include <stdexcept>

#include <lcm/lcm-cpp.hpp>

#include "common/time_source.h"

namespace bookgrasp {

int64_t LoggedMessage::message_utime() const {
  int64_t t = 0;
  MessageTimeSource::peek_utime(data.data(), data.size(), &t);
  return t;
}

std::vector<LoggedMessage> read_lcm_log(const std::string& path) {
  {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw std::runtime_error("cannot open log '" + path + "'");
    unsigned char magic[4] = {0, 0, 0, 0};
    probe.read(reinterpret_cast<char*>(magic), 4);
    // LCM log events start with the sync word 0xEDA1DA01.
    if (probe.gcount() > 0 && !(magic[0] == 0xED && magic[1] == 0xA1 && magic[2] == 0xDA && magic[3] == 0x01))
      throw std::runtime_error("'" + path + "' is not an LCM log (no sync word)");
  }
  lcm::LogFile log(path, "r");
  if (!log.good()) throw std::runtime_error("cannot read LCM log '" + path + "'");
  std::vector<LoggedMessage> out;
  while (const lcm::LogEvent* ev = log.readNextEvent()) {
    LoggedMessage m;
    m.log_utime = ev->timestamp;
    m.channel = ev->channel;
    const auto* b = static_cast<const uint8_t*>(ev->data);
    m.data.assign(b, b + ev->datalen);
    out.push_back(std::move(m));
  }
  return out;
}

void write_lcm_log(const std::string& path, const std::vector<LoggedMessage>& messages) {
  lcm::LogFile log(path, "w");
  if (!log.good()) throw std::runtime_error("cannot write LCM log '" + path + "'");
  for (const auto& m : messages) {
    lcm::LogEvent ev;
    ev.eventnum = 0;
    ev.timestamp = m.log_utime;
    ev.channel = m.channel;
    ev.datalen = static_cast<int32_t>(m.data.size());
    ev.data = const_cast<uint8_t*>(m.data.data());
    if (log.writeEvent(&ev) != 0) throw std::runtime_error("writing '" + path + "' failed");
  }
}

}  // namespace bookgrasp
