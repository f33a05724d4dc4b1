#pragma once
// Shared by the end-to-end tests: run the `sanguis` executable in a fresh
// temporary folder and capture its exit code and output.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

namespace sanguis::testing_cli {

namespace fs = std::filesystem;

inline std::string read_text_file(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

inline std::string shell_quoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

struct CommandResult {
  int code = -1;
  std::string out, err;
};

// A fixture with its own temporary folder `dir_`, removed afterwards.
class SanguisCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::random_device entropy;
    dir_ = fs::temp_directory_path() / ("sanguis_test_" + name + "_" + std::to_string(entropy()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ignored;
    fs::remove_all(dir_, ignored);
  }

  // Runs `sanguis ARGS` with stdout and stderr captured to files.
  CommandResult sanguis(const std::string& args) {
    const fs::path out = dir_ / "stdout.txt";
    const fs::path err = dir_ / "stderr.txt";
    const std::string command = shell_quoted(SANGUIS_BINARY) + " " + args + " >" +
                                shell_quoted(out.string()) + " 2>" + shell_quoted(err.string()) +
                                " </dev/null";
    const int status = std::system(command.c_str());
    CommandResult r;
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.out = read_text_file(out);
    r.err = read_text_file(err);
    return r;
  }

  fs::path dir_;
};

}  // namespace sanguis::testing_cli
