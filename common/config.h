#pragma once
/// @file
/// YAML configuration with validation: every key a service reads is required,
/// every error names the key, and keys nobody read are reported as typos.

#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

namespace bookgrasp {

/// Thrown for a missing, mistyped or out-of-range configuration value. The
/// message names the file and the dotted key, and says what was expected.
class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A read-only view of a YAML mapping that records which keys were read.
///
/// Keys are dotted paths relative to this view ("stereo.num_disparities").
/// Children made with child() share the record with their parent, so after a
/// service has configured itself, unused_keys() on the root lists every key of
/// the file that nothing read.
class Config {
 public:
  /// Loads a YAML file. Throws ConfigError naming the file if it cannot be
  /// read or parsed, or if its top level is not a mapping.
  static Config load_file(const std::string& path);

  /// Parses YAML text; `source` names it in error messages.
  static Config from_string(const std::string& yaml, const std::string& source = "<string>");

  /// Required value of type T (bool, int, int64_t, double, std::string,
  /// std::vector<double>, std::vector<int>, std::vector<std::string>).
  template <typename T>
  T get(const std::string& key) const;

  /// Required number within [min, max]; the error names the key and the range.
  double get_double(const std::string& key, double min, double max) const;
  /// Required integer within [min, max].
  int get_int(const std::string& key, int min, int max) const;
  /// Required string that must be one of `allowed`.
  std::string get_choice(const std::string& key, const std::vector<std::string>& allowed) const;
  /// Required LCM channel name: a non-empty string without spaces.
  std::string get_channel(const std::string& key) const;
  /// Required list of exactly `n` numbers.
  std::vector<double> get_vector(const std::string& key, size_t n) const;

  /// True if the key exists (does not mark it read).
  bool has(const std::string& key) const;
  /// The mapping at `key` as a Config sharing this one's read record.
  Config child(const std::string& key) const;
  /// Keys of this mapping (marks none read).
  std::vector<std::string> keys() const;

  /// Marks `key` and everything under it as read (for sections parsed elsewhere).
  void mark_read(const std::string& key) const;

  /// Every leaf key under this view that was never read, as full dotted paths.
  std::vector<std::string> unused_keys() const;
  /// Throws ConfigError listing unused keys, if any ("unknown key ... (typo?)").
  void require_all_read() const;

  /// The full dotted path of `key` below this view, for messages.
  std::string path_of(const std::string& key) const;
  /// The source file (or name) the configuration came from.
  const std::string& source() const { return shared_->source; }
  /// The YAML text of this view.
  std::string dump() const;
  /// The raw node (marks nothing read).
  const YAML::Node& node() const { return node_; }

 private:
  struct Shared {
    std::string source;
    std::set<std::string> read;
  };
  Config(YAML::Node node, std::string prefix, std::shared_ptr<Shared> shared);
  YAML::Node lookup(const std::string& key) const;
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;

  YAML::Node node_;
  std::string prefix_;
  std::shared_ptr<Shared> shared_;
};

}  // namespace bookgrasp
