#pragma once
// Strict reader for TOML case files (toml++). Every key read is recorded; at the
// end `check_no_unknown_keys()` turns any key that nobody read into an error, so a
// typo ("raduis_m") never silently falls back to a default. Every error names
// the file, the full dotted key path and the reason (InputError).
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/vec3.hpp"

namespace toml {
inline namespace v3 {
class table;
class node;
}  // namespace v3
}  // namespace toml

namespace sanguis {

class ConfigTable {
 public:
  // Parses a whole file; syntax errors become InputError with line and column.
  static ConfigTable parse_file(const std::filesystem::path& file);
  // Parses text (tests, `--set` overrides); `source_name` plays the file's role in messages.
  static ConfigTable parse_string(const std::string& text, const std::string& source_name);

  ConfigTable(const ConfigTable&);
  ConfigTable& operator=(const ConfigTable&);
  ConfigTable(ConfigTable&&) noexcept;
  ConfigTable& operator=(ConfigTable&&) noexcept;
  ~ConfigTable();

  // Replaces (or adds) one value before the case is read, as given on the
  // command line: "simulation.seed=4", "interaction[0].friction=0.3",
  // "particles[1].region_max_m=[0.1, 0.04, 0.2]". The value is TOML. The
  // parent tables must exist; array indices must be in range. Errors name the
  // override as the key. Only on a root table.
  void set_override(const std::string& assignment);

  bool has(const std::string& key) const;

  // Required values: missing or wrong type is an error.
  double get_double(const std::string& key) const;
  std::int64_t get_int(const std::string& key) const;
  bool get_bool(const std::string& key) const;
  std::string get_string(const std::string& key) const;
  Vec3 get_vec3(const std::string& key) const;
  std::array<bool, 3> get_bool3(const std::string& key) const;
  std::vector<Vec3> get_vec3_list(const std::string& key) const;
  std::vector<std::string> get_string_list(const std::string& key) const;
  // An array of rows of `columns` numbers each, e.g. [[t0, v0], [t1, v1]].
  std::vector<std::vector<double>> get_number_rows(const std::string& key,
                                                   std::size_t columns) const;

  // Optional values with a default.
  double get_double(const std::string& key, double fallback) const;
  std::int64_t get_int(const std::string& key, std::int64_t fallback) const;
  bool get_bool(const std::string& key, bool fallback) const;
  std::string get_string(const std::string& key, const std::string& fallback) const;
  Vec3 get_vec3(const std::string& key, const Vec3& fallback) const;
  std::optional<double> find_double(const std::string& key) const;

  // A value that must be one of `choices`.
  std::string get_choice(const std::string& key, const std::vector<std::string>& choices) const;
  std::string get_choice(const std::string& key, const std::vector<std::string>& choices,
                         const std::string& fallback) const;

  // Range-checked reads: error if the value is outside the interval.
  double get_positive(const std::string& key) const;  // > 0
  double get_positive(const std::string& key, double fallback) const;
  double get_non_negative(const std::string& key, double fallback) const;  // >= 0

  // Sub-tables and arrays of tables share the parent's bookkeeping.
  ConfigTable table(const std::string& key) const;
  std::optional<ConfigTable> find_table(const std::string& key) const;
  std::vector<ConfigTable> table_array(const std::string& key) const;  // missing -> empty

  // Throws on the first key never read (toml++ keeps keys sorted: alphabetical order).
  void check_no_unknown_keys() const;

  // Error for this table's `key` with a reason (for checks done by callers).
  [[noreturn]] void fail(const std::string& key, const std::string& reason) const;

  const std::string& source() const { return source_; }
  std::string path_of(const std::string& key) const;

 private:
  struct Shared;
  ConfigTable(std::shared_ptr<Shared> shared, const toml::table* node, std::string prefix);
  const toml::node* lookup(const std::string& key) const;
  const toml::node& require(const std::string& key) const;
  void mark(const std::string& key) const;
  double number(const toml::node& node, const std::string& key) const;

  std::shared_ptr<Shared> shared_;
  const toml::table* node_ = nullptr;
  std::string prefix_;
  std::string source_;
};

}  // namespace sanguis
