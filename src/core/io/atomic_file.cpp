#include "core/io/atomic_file.hpp"

#include <fstream>
#include <stdexcept>
#include <string>
#include <system_error>

namespace sanguis::io {

namespace {

// Best effort: the caller is already reporting a more useful error.
void remove_quietly(const std::filesystem::path& path) {
  std::error_code ignored;
  std::filesystem::remove(path, ignored);
}

}  // namespace

void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write) {
  std::filesystem::path temporary_path = path;
  temporary_path += ".tmp";

  {
    // Binary mode: the bytes written are exactly the bytes on disk, on every
    // platform (no newline translation inside base64 or CSV data).
    std::ofstream out(temporary_path, std::ios::binary | std::ios::trunc);
    if (!out) {
      throw std::runtime_error("cannot open '" + temporary_path.string() +
                               "' for writing (while writing '" + path.string() + "')");
    }
    try {
      write(out);
    } catch (...) {
      out.close();
      remove_quietly(temporary_path);
      throw;
    }
    out.close();  // flushes; a full disk typically shows up here
    if (out.fail()) {
      remove_quietly(temporary_path);
      throw std::runtime_error("write failure on '" + temporary_path.string() +
                               "' (while writing '" + path.string() + "')");
    }
  }

  std::error_code rename_error;
  std::filesystem::rename(temporary_path, path, rename_error);
  if (rename_error) {
    remove_quietly(temporary_path);
    throw std::runtime_error("cannot rename '" + temporary_path.string() + "' to '" +
                             path.string() + "': " + rename_error.message());
  }
}

}  // namespace sanguis::io
