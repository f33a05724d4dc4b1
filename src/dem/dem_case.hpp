#pragma once
// A DEM case file (TOML, keys documented in docs/case-file.md) turned into a
// ready-to-run setup. All validation happens here, before anything is written:
// unknown keys, wrong types, missing or out-of-range values, overlapping initial
// particles and time steps above Tc/10 are InputErrors naming file and key.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "core/config.hpp"
#include "dem/parameter_procedure.hpp"
#include "dem/simulation.hpp"

namespace sanguis::dem {

struct OutputSettings {
  double interval = 0.0;             // [s] between snapshots and CSV rows
  bool vtk = true;                   // write ParaView files
  double checkpoint_interval = 0.0;  // [s]; 0: only at the end
};

struct StopSettings {
  double end_time = 0.0;                      // [s]
  std::optional<double> mean_velocity_below;  // settle criterion [m/s]
  double settle_check_after = 0.0;            // [s] no settle check before this time
};

// One resolved interaction, for the run log and `sanguis params`.
struct ResolvedInteraction {
  std::string first, second;
  bool wall = false;
  bool memory = true;  // false: kt = kr = 0
  ContactParameters parameters;
  double reduced_mass = 0.0;                 // of the check (smallest particles) [kg]
  double contact_time = 0.0;                 // Tc (eq. 2.17) for the smallest particles [s]
  std::optional<ProcedureResult> procedure;  // when derived by §2.4
};

struct DemCase {
  std::string name;
  std::filesystem::path source;
  std::uint64_t seed = 0;
  DemSetup setup;
  OutputSettings output;
  StopSettings stop;
  std::vector<ResolvedInteraction> interactions;
  double smallest_contact_time = 0.0;  // [s]
};

DemCase load_dem_case(const std::filesystem::path& file);
DemCase load_dem_case(const ConfigTable& config, const std::filesystem::path& source);

// Human-readable report of every resolved parameter (run.log).
std::string describe(const DemCase& c);

}  // namespace sanguis::dem
