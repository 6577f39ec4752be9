#include "services/replay/output_diff.h"

#include <algorithm>
#include <cstdint>
#include <cmath>
#include <cstdio>
#include <regex>
#include <sstream>

#include "bookgrasp/introspect.hpp"

namespace bookgrasp {
namespace {

/// "regions[2].normal[0]" -> "regions[*].normal[*]" so array elements aggregate.
std::string fold_indices(const std::string& path) {
  static const std::regex idx(R"(\[[0-9]+\])");
  return std::regex_replace(path, idx, "[*]");
}

bool ignored(const std::string& path, const std::set<std::string>& ignore) {
  if (ignore.empty()) return false;
  const std::string folded = fold_indices(path);
  for (const auto& i : ignore)
    if (path == i || folded == i || (folded.size() >= i.size() && folded.compare(folded.size() - i.size(), i.size(), i) == 0))
      return true;
  return false;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.6g", v);
  return buf;
}

std::string json_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (c == '\n') { o += "\\n"; continue; }
    o += c;
  }
  return o;
}

void compare_fields(const LoggedMessage& a, const LoggedMessage& b, std::map<std::string, FieldDiff>* fields,
                    const std::set<std::string>& ignore, std::string* type) {
  std::vector<FieldValue> fa, fb;
  *type = flatten_encoded(a.data.data(), static_cast<int>(a.data.size()), &fa);
  const std::string tb = flatten_encoded(b.data.data(), static_cast<int>(b.data.size()), &fb);
  if (type->empty() || tb != *type) {
    auto& d = (*fields)["<message type>"];
    d.path = "<message type>";
    ++d.messages;
    d.example = (type->empty() ? "unknown" : *type) + " -> " + (tb.empty() ? "unknown" : tb);
    return;
  }
  std::map<std::string, const FieldValue*> mb;
  for (const auto& f : fb) mb[f.path] = &f;
  std::set<std::string> touched;  // count a folded path once per message
  for (const auto& f : fa) {
    if (ignored(f.path, ignore)) continue;
    auto it = mb.find(f.path);
    const std::string key = fold_indices(f.path);
    double delta = 0;
    std::string example;
    if (it == mb.end()) {
      delta = NAN;
      example = "present -> absent";
    } else if (f.is_number) {
      if (f.number == it->second->number || (std::isnan(f.number) && std::isnan(it->second->number))) continue;
      delta = std::abs(it->second->number - f.number);
      example = number(f.number) + " -> " + number(it->second->number);
    } else {
      if (f.text == it->second->text) continue;
      delta = NAN;
      example = "\"" + f.text + "\" -> \"" + it->second->text + "\"";
    }
    auto& d = (*fields)[key];
    d.path = key;
    if (!touched.count(key)) {
      ++d.messages;
      touched.insert(key);
    }
    if (std::isfinite(delta)) {
      d.max_abs = std::max(d.max_abs, delta);
      d.mean_abs += delta;
    }
    if (d.example.empty()) d.example = f.path + ": " + example;
  }
  for (const auto& f : fb) {
    if (ignored(f.path, ignore)) continue;
    bool in_a = false;
    for (const auto& g : fa)
      if (g.path == f.path) { in_a = true; break; }
    if (in_a) continue;
    auto& d = (*fields)[fold_indices(f.path)];
    d.path = fold_indices(f.path);
    ++d.messages;
    if (d.example.empty()) d.example = f.path + ": absent -> present";
  }
}

}  // namespace

DiffReport diff_outputs(const std::vector<LoggedMessage>& recorded, const std::vector<LoggedMessage>& replayed,
                        const std::set<std::string>& channels_in, const std::set<std::string>& ignore,
                        const std::set<int64_t>& fed_utimes) {
  std::set<std::string> channels = channels_in;
  if (channels.empty())
    for (const auto& m : replayed) channels.insert(m.channel);
  DiffReport report;
  for (const auto& ch : channels) {
    ChannelDiff cd;
    cd.channel = ch;
    // utime -> messages in order, for both sides.
    std::map<int64_t, std::vector<const LoggedMessage*>> rec, rep;
    for (const auto& m : recorded)
      if (m.channel == ch) { rec[m.message_utime()].push_back(&m); ++cd.recorded; }
    for (const auto& m : replayed)
      if (m.channel == ch) { rep[m.message_utime()].push_back(&m); ++cd.replayed; }
    std::map<std::string, FieldDiff> fields;
    for (const auto& [t, list] : rec) {
      auto it = rep.find(t);
      const size_t n = it == rep.end() ? 0 : std::min(list.size(), it->second.size());
      for (size_t k = 0; k < n; ++k) {
        ++cd.matched;
        const auto& a = *list[k];
        const auto& b = *it->second[k];
        std::string type;
        if (a.data == b.data) {
          ++cd.identical;
          if (cd.type.empty()) {
            std::vector<FieldValue> ignore_out;
            cd.type = flatten_encoded(a.data.data(), static_cast<int>(a.data.size()), &ignore_out);
          }
          continue;
        }
        // Bytes differ; they may still be equal on every non-ignored field.
        std::map<std::string, FieldDiff> these;
        compare_fields(a, b, &these, ignore, &type);
        if (cd.type.empty()) cd.type = type;
        if (these.empty()) {
          ++cd.identical;
          continue;
        }
        ++cd.differing;
        for (auto& [k2, d] : these) {
          auto& agg = fields[k2];
          agg.path = d.path;
          agg.messages += d.messages;
          agg.max_abs = std::max(agg.max_abs, d.max_abs);
          agg.mean_abs += d.mean_abs;
          if (agg.example.empty()) agg.example = d.example;
        }
      }
      const int unmatched = static_cast<int>(list.size() - n);
      if (!fed_utimes.empty() && !fed_utimes.count(t)) cd.unreplayable += unmatched;
      else cd.missing += unmatched;
    }
    const int64_t last_recorded = rec.empty() ? INT64_MIN : rec.rbegin()->first;
    for (const auto& [t, list] : rep) {
      auto it = rec.find(t);
      const size_t have = it == rec.end() ? 0 : it->second.size();
      if (list.size() <= have) continue;
      const int surplus = static_cast<int>(list.size() - have);
      if (!fed_utimes.empty() && t > last_recorded) cd.after_log_end += surplus;
      else cd.extra += surplus;
    }
    for (auto& [k, d] : fields) {
      if (d.messages > 0) d.mean_abs /= d.messages;
      cd.fields.push_back(d);
    }
    std::sort(cd.fields.begin(), cd.fields.end(),
              [](const FieldDiff& a, const FieldDiff& b) { return a.max_abs > b.max_abs; });
    report.channels.push_back(cd);
  }
  return report;
}

bool DiffReport::identical() const {
  for (const auto& c : channels)
    if (c.differing || c.missing || c.extra || c.matched + c.unreplayable != c.recorded) return false;
  return true;
}

std::string DiffReport::markdown() const {
  std::ostringstream o;
  o << "| channel | type | recorded | replayed | matched | identical | differing | missing | extra | input not in log "
       "| after log end |\n"
    << "|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& c : channels)
    o << "| " << c.channel << " | " << c.type << " | " << c.recorded << " | " << c.replayed << " | " << c.matched
      << " | " << c.identical << " | " << c.differing << " | " << c.missing << " | " << c.extra << " | "
      << c.unreplayable << " | " << c.after_log_end << " |\n";
  for (const auto& c : channels) {
    if (c.fields.empty()) continue;
    o << "\n### " << c.channel << ": fields that moved\n\n| field | messages | max abs diff | mean abs diff | example |\n"
      << "|---|---|---|---|---|\n";
    for (const auto& f : c.fields)
      o << "| " << f.path << " | " << f.messages << " | " << number(f.max_abs) << " | " << number(f.mean_abs) << " | "
        << f.example << " |\n";
  }
  o << "\n" << (identical() ? "All outputs identical bit for bit." : "Outputs differ.") << "\n";
  return o.str();
}

std::string DiffReport::json() const {
  std::ostringstream o;
  o << "{\"identical\": " << (identical() ? "true" : "false") << ", \"channels\": {";
  bool first = true;
  for (const auto& c : channels) {
    o << (first ? "" : ", ") << "\"" << json_escape(c.channel) << "\": {\"type\": \"" << c.type
      << "\", \"recorded\": " << c.recorded << ", \"replayed\": " << c.replayed << ", \"matched\": " << c.matched
      << ", \"identical\": " << c.identical << ", \"differing\": " << c.differing << ", \"missing\": " << c.missing
      << ", \"extra\": " << c.extra << ", \"unreplayable\": " << c.unreplayable
      << ", \"after_log_end\": " << c.after_log_end << ", \"fields\": [";
    bool ff = true;
    for (const auto& f : c.fields) {
      o << (ff ? "" : ", ") << "{\"path\": \"" << json_escape(f.path) << "\", \"messages\": " << f.messages
        << ", \"max_abs\": " << (std::isfinite(f.max_abs) ? number(f.max_abs) : "null")
        << ", \"example\": \"" << json_escape(f.example) << "\"}";
      ff = false;
    }
    o << "]}";
    first = false;
  }
  o << "}}\n";
  return o.str();
}

}  // namespace bookgrasp
