#include "core/config.hpp"

#include <optional>

#include <toml++/toml.h>
#include <sstream>

namespace sanguis {

struct ConfigTable::Shared {
  toml::table root;
  std::string source;
  std::set<std::string> used;  // full dotted paths that were read
};

namespace {

std::string type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a number";
    case toml::node_type::boolean:
      return "a boolean";
    default:
      return "a date/time";
  }
}

std::string format_double(double v) {
  std::ostringstream s;
  s.precision(6);
  s << v;
  return s.str();
}

}  // namespace

ConfigTable ConfigTable::parse_file(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) {
    throw InputError(file.string(), "", "file does not exist");
  }
  if (std::filesystem::is_directory(file, ec)) {
    throw InputError(file.string(), "", "is a directory, expected a TOML case file");
  }
  try {
    auto shared = std::make_shared<Shared>();
    shared->root = toml::parse_file(file.string());
    shared->source = file.string();
    const toml::table* root = &shared->root;
    return ConfigTable(shared, root, "");
  } catch (const toml::parse_error& e) {
    std::ostringstream why;
    why << "TOML syntax error at line " << e.source().begin.line << ", column "
        << e.source().begin.column << ": " << e.description();
    throw InputError(file.string(), "", why.str());
  }
}

ConfigTable ConfigTable::parse_string(const std::string& text, const std::string& source_name) {
  try {
    auto shared = std::make_shared<Shared>();
    shared->root = toml::parse(text, source_name);
    shared->source = source_name;
    const toml::table* root = &shared->root;
    return ConfigTable(shared, root, "");
  } catch (const toml::parse_error& e) {
    std::ostringstream why;
    why << "TOML syntax error at line " << e.source().begin.line << ", column "
        << e.source().begin.column << ": " << e.description();
    throw InputError(source_name, "", why.str());
  }
}

void ConfigTable::set_override(const std::string& assignment) {
  const std::string where = "--set " + assignment;
  const std::size_t equals = assignment.find('=');
  if (equals == std::string::npos || equals == 0) {
    throw InputError(source_, where, "expected KEY=VALUE, e.g. simulation.seed=3");
  }
  const std::string path = assignment.substr(0, equals);
  toml::table parsed;
  try {
    parsed = toml::parse("value = " + assignment.substr(equals + 1), std::string_view("--set"));
  } catch (const toml::parse_error& e) {
    throw InputError(source_, where,
                     std::string("value is not TOML: ") + std::string(e.description()));
  }
  // Walk "a.b[2].c": an indexed component must name an existing element of an
  // array of tables; a missing plain table is created (an optional table the
  // case leaves out, e.g. [stop]): the reader then refuses it if it is not a
  // key of the case, like a misspelt table in the file.
  toml::table* table = &shared_->root;
  std::size_t begin = 0;
  while (true) {
    const std::size_t dot = path.find('.', begin);
    std::string part =
        path.substr(begin, dot == std::string::npos ? std::string::npos : dot - begin);
    std::optional<std::size_t> index;
    if (const std::size_t bracket = part.find('['); bracket != std::string::npos) {
      const std::size_t close = part.find(']', bracket);
      if (close == std::string::npos || close + 1 != part.size()) {
        throw InputError(source_, where, "bad index in '" + part + "'");
      }
      try {
        index = std::stoul(part.substr(bracket + 1, close - bracket - 1));
      } catch (const std::exception&) {
        throw InputError(source_, where, "bad index in '" + part + "'");
      }
      part = part.substr(0, bracket);
    }
    if (part.empty()) throw InputError(source_, where, "empty key component");
    if (dot == std::string::npos) {
      if (index) throw InputError(source_, where, "the last component cannot be indexed");
      table->insert_or_assign(part, *parsed.get("value"));
      return;
    }
    toml::node* next = table->get(part);
    if (next == nullptr) {
      if (index) throw InputError(source_, where, "no array of tables '" + part + "' in the case");
      next = table->insert(part, toml::table{}).first->second.as_table();
    }
    if (index) {
      toml::array* array = next->as_array();
      if (array == nullptr || *index >= array->size()) {
        throw InputError(source_, where, "'" + part + "' has no element " + std::to_string(*index));
      }
      next = array->get(*index);
    }
    table = next->as_table();
    if (table == nullptr) throw InputError(source_, where, "'" + part + "' is not a table");
    begin = dot + 1;
  }
}

ConfigTable::ConfigTable(std::shared_ptr<Shared> shared, const toml::table* node,
                         std::string prefix)
    : shared_(std::move(shared)), node_(node), prefix_(std::move(prefix)) {
  source_ = shared_->source;
}

ConfigTable::ConfigTable(const ConfigTable&) = default;
ConfigTable& ConfigTable::operator=(const ConfigTable&) = default;
ConfigTable::ConfigTable(ConfigTable&&) noexcept = default;
ConfigTable& ConfigTable::operator=(ConfigTable&&) noexcept = default;
ConfigTable::~ConfigTable() = default;

std::string ConfigTable::path_of(const std::string& key) const {
  return prefix_.empty() ? key : prefix_ + "." + key;
}

void ConfigTable::fail(const std::string& key, const std::string& reason) const {
  throw InputError(source_, path_of(key), reason);
}

const toml::node* ConfigTable::lookup(const std::string& key) const {
  return node_->get(key);
}

void ConfigTable::mark(const std::string& key) const {
  shared_->used.insert(path_of(key));
}

bool ConfigTable::has(const std::string& key) const {
  return lookup(key) != nullptr;
}

const toml::node& ConfigTable::require(const std::string& key) const {
  const toml::node* n = lookup(key);
  if (n == nullptr) fail(key, "required key is missing");
  mark(key);
  return *n;
}

double ConfigTable::number(const toml::node& n, const std::string& key) const {
  if (auto v = n.as_floating_point()) return v->get();
  if (auto v = n.as_integer()) return static_cast<double>(v->get());
  fail(key, "expected a number, got " + type_name(n));
}

double ConfigTable::get_double(const std::string& key) const {
  const double v = number(require(key), key);
  if (!std::isfinite(v)) fail(key, "value must be finite");
  return v;
}

std::int64_t ConfigTable::get_int(const std::string& key) const {
  const toml::node& n = require(key);
  if (auto v = n.as_integer()) return v->get();
  fail(key, "expected an integer, got " + type_name(n));
}

bool ConfigTable::get_bool(const std::string& key) const {
  const toml::node& n = require(key);
  if (auto v = n.as_boolean()) return v->get();
  fail(key, "expected true or false, got " + type_name(n));
}

std::string ConfigTable::get_string(const std::string& key) const {
  const toml::node& n = require(key);
  if (auto v = n.as_string()) return v->get();
  fail(key, "expected a string, got " + type_name(n));
}

Vec3 ConfigTable::get_vec3(const std::string& key) const {
  const toml::node& n = require(key);
  const toml::array* a = n.as_array();
  if (a == nullptr || a->size() != 3) fail(key, "expected an array of 3 numbers");
  Vec3 out;
  for (int k = 0; k < 3; ++k) {
    out[k] = number(*a->get(static_cast<std::size_t>(k)), key);
    if (!std::isfinite(out[k])) fail(key, "components must be finite");
  }
  return out;
}

std::array<bool, 3> ConfigTable::get_bool3(const std::string& key) const {
  const toml::node& n = require(key);
  const toml::array* a = n.as_array();
  if (a == nullptr || a->size() != 3) fail(key, "expected an array of 3 booleans");
  std::array<bool, 3> out{};
  for (std::size_t k = 0; k < 3; ++k) {
    auto b = a->get(k)->as_boolean();
    if (b == nullptr) fail(key, "expected an array of 3 booleans");
    out[k] = b->get();
  }
  return out;
}

std::vector<Vec3> ConfigTable::get_vec3_list(const std::string& key) const {
  const toml::node& n = require(key);
  const toml::array* a = n.as_array();
  if (a == nullptr) fail(key, "expected an array of [x, y, z] arrays");
  std::vector<Vec3> out;
  out.reserve(a->size());
  for (std::size_t i = 0; i < a->size(); ++i) {
    const toml::array* row = a->get(i)->as_array();
    if (row == nullptr || row->size() != 3) {
      fail(key, "entry " + std::to_string(i) + " is not an array of 3 numbers");
    }
    Vec3 v;
    for (std::size_t k = 0; k < 3; ++k) v[static_cast<int>(k)] = number(*row->get(k), key);
    out.push_back(v);
  }
  return out;
}

std::vector<std::vector<double>> ConfigTable::get_number_rows(const std::string& key,
                                                              std::size_t columns) const {
  const toml::node& n = require(key);
  const toml::array* a = n.as_array();
  const std::string shape = "an array of [" + std::to_string(columns) + " numbers] rows";
  if (a == nullptr) fail(key, "expected " + shape);
  std::vector<std::vector<double>> out;
  for (std::size_t i = 0; i < a->size(); ++i) {
    const toml::array* row = a->get(i)->as_array();
    if (row == nullptr || row->size() != columns) {
      fail(key, "entry " + std::to_string(i) + " is not a row of " + std::to_string(columns) +
                    " numbers");
    }
    std::vector<double> values;
    for (std::size_t k = 0; k < columns; ++k) values.push_back(number(*row->get(k), key));
    out.push_back(std::move(values));
  }
  return out;
}

std::vector<std::string> ConfigTable::get_string_list(const std::string& key) const {
  const toml::node& n = require(key);
  const toml::array* a = n.as_array();
  if (a == nullptr) fail(key, "expected an array of strings");
  std::vector<std::string> out;
  for (std::size_t i = 0; i < a->size(); ++i) {
    auto s = a->get(i)->as_string();
    if (s == nullptr) fail(key, "entry " + std::to_string(i) + " is not a string");
    out.push_back(s->get());
  }
  return out;
}

double ConfigTable::get_double(const std::string& key, double fallback) const {
  return has(key) ? get_double(key) : fallback;
}
std::int64_t ConfigTable::get_int(const std::string& key, std::int64_t fallback) const {
  return has(key) ? get_int(key) : fallback;
}
bool ConfigTable::get_bool(const std::string& key, bool fallback) const {
  return has(key) ? get_bool(key) : fallback;
}
std::string ConfigTable::get_string(const std::string& key, const std::string& fallback) const {
  return has(key) ? get_string(key) : fallback;
}
Vec3 ConfigTable::get_vec3(const std::string& key, const Vec3& fallback) const {
  return has(key) ? get_vec3(key) : fallback;
}
std::optional<double> ConfigTable::find_double(const std::string& key) const {
  if (!has(key)) return std::nullopt;
  return get_double(key);
}

std::string ConfigTable::get_choice(const std::string& key,
                                    const std::vector<std::string>& choices) const {
  const std::string v = get_string(key);
  for (const auto& c : choices) {
    if (c == v) return v;
  }
  std::string list;
  for (const auto& c : choices) list += (list.empty() ? "" : ", ") + ("'" + c + "'");
  fail(key, "'" + v + "' is not one of " + list);
}

std::string ConfigTable::get_choice(const std::string& key, const std::vector<std::string>& choices,
                                    const std::string& fallback) const {
  return has(key) ? get_choice(key, choices) : fallback;
}

double ConfigTable::get_positive(const std::string& key) const {
  const double v = get_double(key);
  if (!(v > 0.0)) fail(key, "must be > 0, got " + format_double(v));
  return v;
}
double ConfigTable::get_positive(const std::string& key, double fallback) const {
  return has(key) ? get_positive(key) : fallback;
}
double ConfigTable::get_non_negative(const std::string& key, double fallback) const {
  if (!has(key)) return fallback;
  const double v = get_double(key);
  if (!(v >= 0.0)) fail(key, "must be >= 0, got " + format_double(v));
  return v;
}

ConfigTable ConfigTable::table(const std::string& key) const {
  auto t = find_table(key);
  if (!t) fail(key, "required table is missing");
  return *t;
}

std::optional<ConfigTable> ConfigTable::find_table(const std::string& key) const {
  const toml::node* n = lookup(key);
  if (n == nullptr) return std::nullopt;
  mark(key);
  const toml::table* t = n->as_table();
  if (t == nullptr) fail(key, "expected a table, got " + type_name(*n));
  return ConfigTable(shared_, t, path_of(key));
}

std::vector<ConfigTable> ConfigTable::table_array(const std::string& key) const {
  std::vector<ConfigTable> out;
  const toml::node* n = lookup(key);
  if (n == nullptr) return out;
  mark(key);
  const toml::array* a = n->as_array();
  if (a == nullptr) fail(key, "expected an array of tables ([[" + path_of(key) + "]])");
  for (std::size_t i = 0; i < a->size(); ++i) {
    const toml::table* t = a->get(i)->as_table();
    if (t == nullptr) fail(key, "entry " + std::to_string(i) + " is not a table");
    out.push_back(ConfigTable(shared_, t, path_of(key) + "[" + std::to_string(i) + "]"));
  }
  return out;
}

namespace {
void collect_unknown(const toml::table& t, const std::string& prefix,
                     const std::set<std::string>& used, std::vector<std::string>& unknown) {
  for (const auto& [k, v] : t) {
    const std::string path =
        prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (!used.count(path)) {
      unknown.push_back(path);
      continue;
    }
    if (const toml::table* sub = v.as_table()) {
      collect_unknown(*sub, path, used, unknown);
    } else if (const toml::array* arr = v.as_array()) {
      for (std::size_t i = 0; i < arr->size(); ++i) {
        if (const toml::table* sub = arr->get(i)->as_table()) {
          collect_unknown(*sub, path + "[" + std::to_string(i) + "]", used, unknown);
        }
      }
    }
  }
}
}  // namespace

void ConfigTable::check_no_unknown_keys() const {
  std::vector<std::string> unknown;
  collect_unknown(*node_, prefix_, shared_->used, unknown);
  if (!unknown.empty()) {
    throw InputError(source_, unknown.front(),
                     "unknown key (misspelt, or not valid here; see docs/case-file.md)");
  }
}

}  // namespace sanguis
