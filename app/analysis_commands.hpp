#pragma once
// `sanguis analyze`, `sanguis ensemble` and `sanguis calibrate`: the
// post-processing and parameter-study commands over DEM run folders.
#include <CLI/CLI.hpp>
#include <functional>

namespace sanguis::app {

// Adds the three subcommands to `app`; the returned function runs the one that
// was parsed (returns true when it did). Runs are started as child processes
// of this same executable (/proc/self/exe).
std::function<bool()> add_analysis_commands(CLI::App& app);

}  // namespace sanguis::app
