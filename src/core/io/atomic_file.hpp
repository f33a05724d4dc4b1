#pragma once
// Crash-safe file output. Every result file (VTK frames, .pvd indices, CSV
// rewrites on restart) goes through this helper so that a run killed at any
// moment leaves either the previous complete file or the new complete file,
// never a truncated one that ParaView or a post-processing script chokes on.
#include <filesystem>
#include <functional>
#include <ostream>

namespace sanguis::io {

// Calls `write` on a stream opened on `path` + ".tmp" (same directory, so the
// final rename stays on one filesystem and is atomic), then renames the
// temporary file over `path`.
//
// Throws std::runtime_error naming the path if the temporary file cannot be
// opened (e.g. the directory does not exist), if writing or closing fails
// (e.g. disk full) or if the rename fails; the temporary file is removed and
// `path` is left untouched in that case. Exceptions thrown by `write` itself
// propagate unchanged, also after removing the temporary file.
//
// This protects against the process dying (crash, kill, wall-time limit). It
// does not fsync, so after a power loss the file system may still lose the
// newest version; output is written far too often for fsync to be worth it.
void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write);

}  // namespace sanguis::io
