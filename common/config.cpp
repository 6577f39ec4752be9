#include "common/config.h"

#include <cmath>
#include <fstream>
#include <sstream>

namespace bookgrasp {
namespace {

std::vector<std::string> split_dots(const std::string& key) {
  std::vector<std::string> parts;
  std::stringstream ss(key);
  std::string part;
  while (std::getline(ss, part, '.')) parts.push_back(part);
  return parts;
}

void collect_leaves(const YAML::Node& node, const std::string& prefix, std::vector<std::string>* out) {
  if (node.IsMap()) {
    for (const auto& kv : node) {
      const std::string k = kv.first.as<std::string>();
      collect_leaves(kv.second, prefix.empty() ? k : prefix + "." + k, out);
    }
  } else {
    out->push_back(prefix);
  }
}

}  // namespace

Config::Config(YAML::Node node, std::string prefix, std::shared_ptr<Shared> shared)
    : node_(std::move(node)), prefix_(std::move(prefix)), shared_(std::move(shared)) {}

Config Config::load_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError("config file '" + path + "' cannot be read: check the path given with --config");
  std::stringstream ss;
  ss << in.rdbuf();
  return from_string(ss.str(), path);
}

Config Config::from_string(const std::string& yaml, const std::string& source) {
  YAML::Node node;
  try {
    node = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    throw ConfigError(source + ": not valid YAML: " + e.what());
  }
  if (!node.IsMap()) throw ConfigError(source + ": the top level must be a mapping of keys to values");
  auto shared = std::make_shared<Shared>();
  shared->source = source;
  return Config(node, "", shared);
}

std::string Config::path_of(const std::string& key) const {
  return prefix_.empty() ? key : prefix_ + "." + key;
}

YAML::Node Config::lookup(const std::string& key) const {
  // yaml-cpp pitfalls: non-const operator[] inserts keys and Node assignment
  // overwrites the referenced node, so walk with const access and reset().
  YAML::Node cur;
  cur.reset(node_);
  for (const auto& part : split_dots(key)) {
    if (!cur.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
    const YAML::Node& const_cur = cur;
    const YAML::Node next = const_cur[part];
    if (!next.IsDefined()) return YAML::Node(YAML::NodeType::Undefined);
    cur.reset(next);
  }
  return cur;
}

void Config::fail(const std::string& key, const std::string& what) const {
  throw ConfigError(shared_->source + ": key '" + path_of(key) + "' " + what);
}

bool Config::has(const std::string& key) const { return lookup(key).IsDefined(); }

template <typename T>
T Config::get(const std::string& key) const {
  const YAML::Node n = lookup(key);
  if (!n.IsDefined() || n.IsNull()) fail(key, "is missing: add it (see the service's default file in config/)");
  T value;
  try {
    value = n.as<T>();
  } catch (const YAML::Exception&) {
    fail(key, "has the wrong type (value: '" + YAML::Dump(n) + "')");
  }
  if constexpr (std::is_floating_point_v<T>) {
    if (!std::isfinite(value)) fail(key, "must be a finite number");
  }
  shared_->read.insert(path_of(key));
  return value;
}

template bool Config::get<bool>(const std::string&) const;
template int Config::get<int>(const std::string&) const;
template int64_t Config::get<int64_t>(const std::string&) const;
template double Config::get<double>(const std::string&) const;
template std::string Config::get<std::string>(const std::string&) const;
template std::vector<double> Config::get<std::vector<double>>(const std::string&) const;
template std::vector<int> Config::get<std::vector<int>>(const std::string&) const;
template std::vector<std::string> Config::get<std::vector<std::string>>(const std::string&) const;

double Config::get_double(const std::string& key, double min, double max) const {
  const double v = get<double>(key);
  if (v < min || v > max) {
    std::ostringstream os;
    os << "= " << v << " is out of range [" << min << ", " << max << "]";
    fail(key, os.str());
  }
  return v;
}

int Config::get_int(const std::string& key, int min, int max) const {
  const int v = get<int>(key);
  if (v < min || v > max) {
    std::ostringstream os;
    os << "= " << v << " is out of range [" << min << ", " << max << "]";
    fail(key, os.str());
  }
  return v;
}

std::string Config::get_choice(const std::string& key, const std::vector<std::string>& allowed) const {
  const std::string v = get<std::string>(key);
  for (const auto& a : allowed)
    if (a == v) return v;
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
  fail(key, "= '" + v + "' is not one of: " + list);
}

std::string Config::get_channel(const std::string& key) const {
  const std::string v = get<std::string>(key);
  if (v.empty()) fail(key, "channel name must not be empty");
  if (v.find_first_of(" \t\n") != std::string::npos) fail(key, "= '" + v + "': a channel name has no spaces");
  return v;
}

std::vector<double> Config::get_vector(const std::string& key, size_t n) const {
  const auto v = get<std::vector<double>>(key);
  if (v.size() != n) fail(key, "must be a list of " + std::to_string(n) + " numbers, has " + std::to_string(v.size()));
  for (double x : v)
    if (!std::isfinite(x)) fail(key, "must contain finite numbers only");
  return v;
}

Config Config::child(const std::string& key) const {
  const YAML::Node n = lookup(key);
  if (!n.IsDefined() || n.IsNull()) fail(key, "is missing: add the section (see the service's default file in config/)");
  if (!n.IsMap()) fail(key, "must be a mapping (a section of keys)");
  return Config(n, path_of(key), shared_);
}

std::vector<std::string> Config::keys() const {
  std::vector<std::string> out;
  for (const auto& kv : node_) out.push_back(kv.first.as<std::string>());
  return out;
}

void Config::mark_read(const std::string& key) const {
  const YAML::Node n = lookup(key);
  if (!n.IsDefined()) fail(key, "is missing");
  std::vector<std::string> leaves;
  collect_leaves(n, path_of(key), &leaves);
  for (const auto& l : leaves) shared_->read.insert(l);
}

std::vector<std::string> Config::unused_keys() const {
  std::vector<std::string> leaves;
  collect_leaves(node_, prefix_, &leaves);
  std::vector<std::string> out;
  for (const auto& l : leaves)
    if (!shared_->read.count(l)) out.push_back(l);
  return out;
}

void Config::require_all_read() const {
  const auto unused = unused_keys();
  if (unused.empty()) return;
  std::string list;
  for (const auto& u : unused) list += (list.empty() ? "'" : ", '") + u + "'";
  throw ConfigError(shared_->source + ": unknown key " + list + " (a typo? nothing reads it)");
}

std::string Config::dump() const {
  YAML::Emitter e;
  e << node_;
  return e.c_str();
}

}  // namespace bookgrasp
