#include "services/replay/component_registry.h"

#include <stdexcept>

namespace bookgrasp {

void ComponentRegistry::add(ServiceDescription d) { entries_[d.name] = std::move(d); }

std::vector<std::string> ComponentRegistry::names() const {
  std::vector<std::string> out;
  for (const auto& [n, d] : entries_) out.push_back(n);
  return out;
}

const ServiceDescription& ComponentRegistry::get(const std::string& name) const {
  auto it = entries_.find(name);
  if (it == entries_.end()) {
    std::string known;
    for (const auto& n : names()) known += (known.empty() ? "" : ", ") + n;
    throw std::runtime_error("unknown service '" + name + "'; known: " + (known.empty() ? "(none)" : known));
  }
  return it->second;
}

std::unique_ptr<Component> ComponentRegistry::make(const std::string& name, const std::string& config_path,
                                                   const std::string& source_dir) const {
  const ServiceDescription& d = get(name);
  const std::string path = config_path.empty() ? source_dir + "/" + d.default_config : config_path;
  const Config root = Config::load_file(path);
  root.mark_read("service");  // runtime settings: the composition ignores them
  auto component = d.factory(root);
  root.require_all_read();
  return component;
}

}  // namespace bookgrasp
