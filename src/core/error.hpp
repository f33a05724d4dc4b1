#pragma once
// Error types. The library never calls exit(): it throws, and the executable
// maps each type to a message and an exit code (app/main.cpp).
#include <stdexcept>
#include <string>

namespace sanguis {

// Bad user input: a case file, a command-line value, an unreadable file.
// The message always names the file and the key (or flag) and says why.
class InputError : public std::runtime_error {
 public:
  InputError(const std::string& file, const std::string& key, const std::string& reason)
      : std::runtime_error(compose(file, key, reason)), file_(file), key_(key), reason_(reason) {}

  const std::string& file() const { return file_; }
  const std::string& key() const { return key_; }
  const std::string& reason() const { return reason_; }

 private:
  static std::string compose(const std::string& file, const std::string& key,
                             const std::string& reason) {
    std::string where = file.empty() ? std::string("input") : file;
    if (!key.empty()) where += ": key '" + key + "'";
    return where + ": " + reason;
  }
  std::string file_, key_, reason_;
};

// A run that went wrong while stepping (NaN, overlap beyond bound, ...).
class SimulationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace sanguis
