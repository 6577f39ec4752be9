#include "services/channel_echo/field_condition.h"

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace bookgrasp {

namespace {

const FieldValue* find(const std::vector<FieldValue>& fields, const std::string& path) {
  for (const auto& f : fields)
    if (f.path == path) return &f;
  return nullptr;
}

std::string number_text(double v) {
  // Integers (utimes, ids, counts, enums) exactly; other numbers with 10 significant digits.
  if (v == std::floor(v) && std::fabs(v) < 9007199254740992.0) return std::to_string(static_cast<int64_t>(v));
  std::ostringstream o;
  o.precision(10);
  o << v;
  return o.str();
}

}  // namespace

FieldCondition FieldCondition::parse(const std::string& text) {
  FieldCondition c;
  const auto ne = text.find("!=");
  const auto eq = text.find('=');
  if (ne != std::string::npos && ne < eq) {
    c.path = text.substr(0, ne);
    c.equal = false;
    c.value = text.substr(ne + 2);
  } else if (eq != std::string::npos) {
    c.path = text.substr(0, eq);
    c.value = text.substr(eq + 1);
  }
  if (c.path.empty() || eq == std::string::npos)
    throw std::invalid_argument("condition '" + text + "' is not PATH=VALUE or PATH!=VALUE");
  return c;
}

bool FieldCondition::has_field(const std::vector<FieldValue>& fields) const {
  return find(fields, path) != nullptr;
}

bool FieldCondition::holds(const std::vector<FieldValue>& fields) const {
  const FieldValue* f = find(fields, path);
  if (!f) return false;
  bool same;
  if (f->is_number) {
    char* end = nullptr;
    const double want = std::strtod(value.c_str(), &end);
    same = end != value.c_str() && *end == '\0' && f->number == want;
  } else {
    same = f->text == value;
  }
  return same == equal;
}

std::string format_fields(const std::vector<FieldValue>& fields, const std::vector<std::string>& select) {
  std::string out;
  auto add = [&](const FieldValue& f) {
    if (!out.empty()) out += ' ';
    out += f.path + "=" + (f.is_number ? number_text(f.number) : "\"" + f.text + "\"");
  };
  if (select.empty()) {
    for (const auto& f : fields) add(f);
  } else {
    for (const auto& s : select) {
      if (const FieldValue* f = find(fields, s))
        add(*f);
      else
        out += (out.empty() ? "" : " ") + s + "=<no such field>";
    }
  }
  return out;
}

}  // namespace bookgrasp
