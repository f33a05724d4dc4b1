// Tests for the strict TOML reader (core/config.hpp): every error is an
// InputError naming the file, the full dotted key path and the reason; typos are
// caught by check_no_unknown_keys() in nested tables and arrays of tables.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "core/config.hpp"
#include "core/error.hpp"

namespace sanguis {
namespace {

namespace fs = std::filesystem;

ConfigTable parse(const std::string& text) {
  return ConfigTable::parse_string(text, "case.toml");
}

// Runs `action`, which must throw an InputError, and returns it.
InputError expect_input_error(const std::function<void()>& action) {
  try {
    action();
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "expected an InputError, none was thrown";
  return InputError("", "", "");
}

// Checks file, key and a fragment of the reason, and that what() composes them.
void expect_error(const InputError& e, const std::string& key, const std::string& reason_part) {
  EXPECT_EQ(e.file(), "case.toml");
  EXPECT_EQ(e.key(), key);
  EXPECT_NE(e.reason().find(reason_part), std::string::npos)
      << "reason '" << e.reason() << "' lacks '" << reason_part << "'";
  const std::string what = e.what();
  EXPECT_NE(what.find("case.toml"), std::string::npos) << what;
  if (!key.empty()) {
    EXPECT_NE(what.find("'" + key + "'"), std::string::npos) << what;
  }
}

// --- Reading values -------------------------------------------------------------

TEST(ConfigTable, ReadsValuesOfEveryType) {
  const ConfigTable c = parse(R"(
x = 1.5
n = 42
flag = true
label = "glass"
v = [1.0, 2, -3.5]
b3 = [true, false, true]
list = [[0.0, 1.0, 2.0], [3, 4, 5]]
names = ["a", "b"]
)");
  EXPECT_EQ(c.get_double("x"), 1.5);
  EXPECT_EQ(c.get_int("n"), 42);
  EXPECT_TRUE(c.get_bool("flag"));
  EXPECT_EQ(c.get_string("label"), "glass");
  EXPECT_EQ(c.get_vec3("v"), (Vec3{1.0, 2.0, -3.5}));
  EXPECT_EQ(c.get_bool3("b3"), (std::array<bool, 3>{true, false, true}));
  const std::vector<Vec3> list = c.get_vec3_list("list");
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[1], (Vec3{3.0, 4.0, 5.0}));
  EXPECT_EQ(c.get_string_list("names"), (std::vector<std::string>{"a", "b"}));
  EXPECT_NO_THROW(c.check_no_unknown_keys());
}

TEST(ConfigTable, IntegerIsAcceptedWhereADoubleIsExpected) {
  const ConfigTable c = parse("end_time_s = 2\nnegative = -7\n");
  EXPECT_EQ(c.get_double("end_time_s"), 2.0);
  EXPECT_EQ(c.get_positive("end_time_s"), 2.0);
  EXPECT_EQ(c.get_double("negative", 0.0), -7.0);
}

TEST(ConfigTable, DefaultsApplyOnlyWhenTheKeyIsAbsent) {
  const ConfigTable c = parse("present = 3.0\n");
  EXPECT_EQ(c.get_double("absent", 9.0), 9.0);
  EXPECT_EQ(c.get_double("present", 9.0), 3.0);
  EXPECT_EQ(c.get_int("absent", 5), 5);
  EXPECT_EQ(c.get_string("absent", "x"), "x");
  EXPECT_FALSE(c.get_bool("absent", false));
  EXPECT_EQ(c.get_vec3("absent", {1, 2, 3}), (Vec3{1, 2, 3}));
  EXPECT_FALSE(c.find_double("absent").has_value());
  EXPECT_EQ(c.find_double("present"), 3.0);
  EXPECT_EQ(c.get_choice("absent", {"a", "b"}, "b"), "b");
  EXPECT_FALSE(c.has("absent"));
  EXPECT_TRUE(c.has("present"));
}

// --- Missing keys and wrong types -------------------------------------------------

TEST(ConfigTable, MissingRequiredKeyNamesTheFullPath) {
  const ConfigTable c = parse("[simulation]\nname = \"x\"\n");
  const ConfigTable sim = c.table("simulation");
  expect_error(expect_input_error([&] { sim.get_double("end_time_s"); }), "simulation.end_time_s",
               "required key is missing");
  expect_error(expect_input_error([&] { sim.get_string("integrator"); }), "simulation.integrator",
               "required key is missing");
  expect_error(expect_input_error([&] { c.table("domain"); }), "domain",
               "required table is missing");
}

TEST(ConfigTable, StringWhereANumberIsExpected) {
  const ConfigTable c = parse("[simulation]\nend_time_s = \"1.0\"\n");
  expect_error(expect_input_error([&] { c.table("simulation").get_double("end_time_s"); }),
               "simulation.end_time_s", "expected a number, got a string");
  // The optional form checks the type too: a wrong type never falls back to the default.
  expect_error(expect_input_error([&] { c.table("simulation").get_double("end_time_s", 1.0); }),
               "simulation.end_time_s", "expected a number, got a string");
}

TEST(ConfigTable, OtherWrongTypes) {
  const ConfigTable c = parse(R"(
count = 2.5
flag = 1
name = 3
vector = "up"
table_value = 4
list = "not a list"
names = ["a", 2]
bools = [true, 1, false]
)");
  expect_error(expect_input_error([&] { c.get_int("count"); }), "count",
               "expected an integer, got a number");
  expect_error(expect_input_error([&] { c.get_bool("flag"); }), "flag",
               "expected true or false, got an integer");
  expect_error(expect_input_error([&] { c.get_string("name"); }), "name",
               "expected a string, got an integer");
  expect_error(expect_input_error([&] { c.get_vec3("vector"); }), "vector",
               "expected an array of 3 numbers");
  expect_error(expect_input_error([&] { c.table("table_value"); }), "table_value",
               "expected a table, got an integer");
  expect_error(expect_input_error([&] { c.get_vec3_list("list"); }), "list",
               "expected an array of [x, y, z] arrays");
  expect_error(expect_input_error([&] { c.get_string_list("names"); }), "names",
               "entry 1 is not a string");
  expect_error(expect_input_error([&] { c.get_bool3("bools"); }), "bools",
               "expected an array of 3 booleans");
  expect_error(expect_input_error([&] { c.table_array("count"); }), "count",
               "expected an array of tables");
}

TEST(ConfigTable, Vec3NeedsExactlyThreeNumbers) {
  const ConfigTable c = parse(R"(
[domain]
max_m = [1.0, 2.0]
four = [1, 2, 3, 4]
text = [1.0, "2", 3.0]
list = [[1, 2, 3], [4, 5]]
)");
  const ConfigTable d = c.table("domain");
  expect_error(expect_input_error([&] { d.get_vec3("max_m"); }), "domain.max_m",
               "expected an array of 3 numbers");
  expect_error(expect_input_error([&] { d.get_vec3("four"); }), "domain.four",
               "expected an array of 3 numbers");
  expect_error(expect_input_error([&] { d.get_vec3("text"); }), "domain.text",
               "expected a number, got a string");
  expect_error(expect_input_error([&] { d.get_vec3_list("list"); }), "domain.list",
               "entry 1 is not an array of 3 numbers");
}

TEST(ConfigTable, NonFiniteNumbersAreRejected) {
  const ConfigTable c = parse("a = inf\nb = nan\nv = [0.0, -inf, 1.0]\n");
  expect_error(expect_input_error([&] { c.get_double("a"); }), "a", "finite");
  expect_error(expect_input_error([&] { c.get_double("b"); }), "b", "finite");
  expect_error(expect_input_error([&] { c.get_positive("a"); }), "a", "finite");
  expect_error(expect_input_error([&] { c.get_vec3("v"); }), "v", "finite");
}

// --- Choices and ranges ----------------------------------------------------------

TEST(ConfigTable, BadChoiceListsTheChoices) {
  const ConfigTable c = parse("[simulation]\nintegrator = \"rk4\"\n");
  const InputError e = expect_input_error([&] {
    c.table("simulation").get_choice("integrator", {"euler", "leapfrog", "adams_bashforth_2"});
  });
  expect_error(e, "simulation.integrator", "'rk4' is not one of");
  EXPECT_NE(e.reason().find("'euler', 'leapfrog', 'adams_bashforth_2'"), std::string::npos)
      << e.reason();
  // With a default, a present but bad value is still an error.
  expect_error(expect_input_error(
                   [&] { c.table("simulation").get_choice("integrator", {"euler"}, "euler"); }),
               "simulation.integrator", "is not one of 'euler'");
  EXPECT_EQ(parse("k = \"euler\"").get_choice("k", {"euler", "leapfrog"}), "euler");
}

TEST(ConfigTable, PositiveRejectsZeroAndNegative) {
  const ConfigTable c = parse("zero = 0.0\nint_zero = 0\nnegative = -1.5\nsmall = 1e-300\n");
  expect_error(expect_input_error([&] { c.get_positive("zero"); }), "zero", "must be > 0, got 0");
  expect_error(expect_input_error([&] { c.get_positive("int_zero"); }), "int_zero",
               "must be > 0, got 0");
  expect_error(expect_input_error([&] { c.get_positive("negative"); }), "negative",
               "must be > 0, got -1.5");
  expect_error(expect_input_error([&] { c.get_positive("negative", 1.0); }), "negative",
               "must be > 0");
  EXPECT_EQ(c.get_positive("small"), 1e-300);
  EXPECT_EQ(c.get_positive("absent", 2.0), 2.0);
}

TEST(ConfigTable, NonNegativeAcceptsZeroRejectsNegative) {
  const ConfigTable c = parse("zero = 0.0\nnegative = -0.25\n");
  EXPECT_EQ(c.get_non_negative("zero", 1.0), 0.0);
  EXPECT_EQ(c.get_non_negative("absent", 1.0), 1.0);
  expect_error(expect_input_error([&] { c.get_non_negative("negative", 1.0); }), "negative",
               "must be >= 0, got -0.25");
}

TEST(ConfigTable, FailNamesTheDottedPath) {
  const ConfigTable c = parse("[[particles]]\ncount = 1\n[[particles]]\ncount = 2\n");
  const auto groups = c.table_array("particles");
  ASSERT_EQ(groups.size(), 2u);
  EXPECT_EQ(groups[1].path_of("count"), "particles[1].count");
  expect_error(expect_input_error([&] { groups[1].fail("count", "too many"); }),
               "particles[1].count", "too many");
  EXPECT_EQ(groups[0].source(), "case.toml");
  EXPECT_TRUE(c.table_array("absent").empty());
}

// --- Unknown keys -----------------------------------------------------------------

TEST(ConfigTable, UnknownKeyAtTopLevel) {
  const ConfigTable c = parse("end_time_s = 1.0\nend_tme_s = 1.0\n");
  c.get_double("end_time_s");
  expect_error(expect_input_error([&] { c.check_no_unknown_keys(); }), "end_tme_s", "unknown key");
}

TEST(ConfigTable, UnknownKeyInNestedTable) {
  const ConfigTable c = parse(R"(
[simulation]
end_time_s = 1.0
end_tme_s = 2.0
[simulation.extra]
depth = 1
)");
  const ConfigTable sim = c.table("simulation");
  sim.get_double("end_time_s");
  sim.table("extra").get_int("depth");
  const InputError e = expect_input_error([&] { c.check_no_unknown_keys(); });
  expect_error(e, "simulation.end_tme_s", "unknown key");
  EXPECT_NE(e.reason().find("docs/case-file.md"), std::string::npos);
}

TEST(ConfigTable, UnknownKeyDeepInsideNestedTables) {
  const ConfigTable c = parse("[a.b]\nc = 1\nd = 2\n");
  c.table("a").table("b").get_int("c");
  expect_error(expect_input_error([&] { c.check_no_unknown_keys(); }), "a.b.d", "unknown key");
}

TEST(ConfigTable, WholeUnreadTableIsReportedByItsName) {
  const ConfigTable c = parse("[simulation]\nend_time_s = 1.0\n[outptu]\ninterval_s = 0.1\n");
  c.table("simulation").get_double("end_time_s");
  expect_error(expect_input_error([&] { c.check_no_unknown_keys(); }), "outptu", "unknown key");
}

TEST(ConfigTable, UnknownKeyInArrayOfTablesNamesTheEntry) {
  const ConfigTable c = parse(R"(
[[particles]]
radius_m = 1e-3

[[particles]]
raduis_m = 1e-3
)");
  for (const ConfigTable& g : c.table_array("particles")) g.get_positive("radius_m", 1e-3);
  expect_error(expect_input_error([&] { c.check_no_unknown_keys(); }), "particles[1].raduis_m",
               "unknown key");
}

TEST(ConfigTable, NoErrorWhenEveryKeyWasRead) {
  const ConfigTable c = parse(R"(
[simulation]
end_time_s = 1.0
[[particles]]
radius_m = 1e-3
[[particles]]
radius_m = 2e-3
)");
  c.table("simulation").get_double("end_time_s");
  for (const ConfigTable& g : c.table_array("particles")) g.get_double("radius_m");
  EXPECT_NO_THROW(c.check_no_unknown_keys());
}

TEST(ConfigTable, KeyCheckedOnlyWithHasIsStillUnknown) {
  // has() does not count as reading: a key that is only probed is still reported.
  const ConfigTable c = parse("x = 1\n");
  EXPECT_TRUE(c.has("x"));
  expect_error(expect_input_error([&] { c.check_no_unknown_keys(); }), "x", "unknown key");
}

TEST(ConfigTable, CopiesShareTheBookkeeping) {
  const ConfigTable c = parse("[s]\na = 1\nb = 2\n");
  const ConfigTable first = c.table("s");
  const ConfigTable second = c.table("s");  // NOLINT: another view of the same table
  ConfigTable copy = first;
  copy.get_int("a");
  second.get_int("b");
  EXPECT_NO_THROW(c.check_no_unknown_keys());
}

// --- Syntax errors and files ------------------------------------------------------

TEST(ConfigTable, SyntaxErrorReportsTheLine) {
  const InputError e =
      expect_input_error([] { parse("[simulation]\nend_time_s = 1.0\nname = \"unterminated\n"); });
  expect_error(e, "", "TOML syntax error at line 3");
  EXPECT_NE(e.reason().find("column"), std::string::npos) << e.reason();
}

TEST(ConfigTable, SyntaxErrorForDuplicateKeyAndMissingValue) {
  expect_error(expect_input_error([] { parse("a = 1\nb = 2\n\na = 3\n"); }), "",
               "TOML syntax error at line 4");
  expect_error(expect_input_error([] { parse("[domain]\nmin_m =\n"); }), "",
               "TOML syntax error at line 2");
}

class ConfigFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::random_device entropy;
    dir_ = fs::temp_directory_path() / ("sanguis_test_config_" + std::to_string(entropy()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }
  fs::path dir_;
};

TEST_F(ConfigFileTest, ParsesAFileAndNamesItInErrors) {
  const fs::path file = dir_ / "good.toml";
  std::ofstream(file) << "[simulation]\nend_time_s = 0.5\n";
  const ConfigTable c = ConfigTable::parse_file(file);
  EXPECT_EQ(c.source(), file.string());
  EXPECT_EQ(c.table("simulation").get_double("end_time_s"), 0.5);
  try {
    c.table("simulation").get_int("steps");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), file.string());
    EXPECT_EQ(e.key(), "simulation.steps");
  }
}

TEST_F(ConfigFileTest, MissingFileAndDirectory) {
  const fs::path missing = dir_ / "missing.toml";
  try {
    ConfigTable::parse_file(missing);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), missing.string());
    EXPECT_EQ(e.key(), "");
    EXPECT_NE(e.reason().find("does not exist"), std::string::npos) << e.reason();
  }
  try {
    ConfigTable::parse_file(dir_);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), dir_.string());
    EXPECT_NE(e.reason().find("is a directory"), std::string::npos) << e.reason();
  }
}

TEST_F(ConfigFileTest, SyntaxErrorInAFile) {
  const fs::path file = dir_ / "bad.toml";
  std::ofstream(file) << "# comment\n[simulation]\nend_time_s = = 1\n";
  try {
    ConfigTable::parse_file(file);
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.file(), file.string());
    EXPECT_NE(e.reason().find("TOML syntax error at line 3"), std::string::npos) << e.reason();
  }
}

}  // namespace
}  // namespace sanguis

namespace sanguis {
namespace {

TEST(ConfigOverride, ReplacesAddsAndIndexesArraysOfTables) {
  ConfigTable c = ConfigTable::parse_string(
      "[simulation]\nseed = 1\n[[particles]]\ncount = 5\n[[particles]]\ncount = 7\n", "case.toml");
  c.set_override("simulation.seed=4");
  c.set_override("particles[1].count=9");
  c.set_override("simulation.gravity_m_s2=[0.0, 0.0, -1.0]");
  EXPECT_EQ(c.table("simulation").get_int("seed"), 4);
  EXPECT_EQ(c.table("simulation").get_vec3("gravity_m_s2").z, -1.0);
  EXPECT_EQ(c.table_array("particles")[0].get_int("count"), 5);
  EXPECT_EQ(c.table_array("particles")[1].get_int("count"), 9);
  // A table the case leaves out is created (the case reader checks its keys).
  c.set_override("stop.mean_velocity_below_m_s=1e-3");
  EXPECT_EQ(c.table("stop").get_double("mean_velocity_below_m_s"), 1e-3);
}

TEST(ConfigOverride, BadOverridesNameThemselves) {
  ConfigTable c = ConfigTable::parse_string("[simulation]\nseed = 1\n", "case.toml");
  const auto message = [&](const std::string& o) {
    try {
      c.set_override(o);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message("simulation.seed").find("KEY=VALUE"), std::string::npos);
  EXPECT_NE(message("simulation.seed=[1,").find("not TOML"), std::string::npos);
  EXPECT_NE(message("particles[0].count=3").find("no array of tables 'particles'"),
            std::string::npos);
  EXPECT_NE(message("simulation[2].seed=1").find("no element 2"), std::string::npos);
  EXPECT_NE(message("simulation.seed[0]=1").find("cannot be indexed"), std::string::npos);
  EXPECT_NE(message("simulation.seed=1").find("no error"), std::string::npos);
}

}  // namespace
}  // namespace sanguis
