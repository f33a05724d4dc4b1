#pragma once
// One analysis of a DEM run folder: every measure of thesis ch. 3 / app. B
// that applies to a dam break (run-out and height, flow regime, mean velocity
// and centre of mass over time, force distribution, fabric, coordination,
// wall contacts and loads), computed from the written frames, and written as
// CSV files (plus a filtered force network for ParaView) that
// scripts/plot_analysis.py draws.
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "dem/analysis/collapse.hpp"
#include "dem/analysis/contact_statistics.hpp"
#include "dem/analysis/run_output.hpp"
#include "dem/analysis/top_view.hpp"

namespace sanguis::dem::analysis {

struct AnalysisOptions {
  // Frame for the final state (L_inf, H_inf); < 0: the last frame.
  double final_time = -1.0;
  // Frame for the initial column (L0, H0) and the contact network; unset: the
  // removal time of the first obstacle removed during the run (the gate), else
  // the first frame.
  std::optional<double> initial_time;
  // Geometry of the top view; unset: from the particles of the initial frame
  // (back wall = smallest x - r, floor = smallest z - r, width = y extent).
  std::optional<double> wall_x, floor_z, y_min, y_max;
  std::optional<double> pixel;      // unset: half the mean particle radius
  double gravity = 9.81;            // |g| [m/s^2] for sqrt(g H0), tau_c and loads
  double strong_force_ratio = 5.0;  // network of Fc / <Fc> above this (Fig. 3.11b)
  std::size_t fabric_bins = 36;
  RegimeThresholds regime;
  // The "bulk" coordination region: the column (back wall to the gate, floor
  // to H0, across the width) less this margin on every side [m]; unset: two
  // mean bounding diameters of the initial frame's particles (four mean
  // bounding radii), the layers where walls and the free surface take the
  // place of neighbours.
  std::optional<double> bulk_margin;
};

struct TimeSample {
  double time = 0.0;
  double mean_speed = 0.0;
  Vec3 centre_of_mass;
};

struct RunAnalysis {
  std::string run;                              // folder analysed
  double initial_time = 0.0, final_time = 0.0;  // frames measured [s]
  double release_time = 0.0;  // origin of the time series: the gate's removal, if any [s]
  double wall_x = 0.0, floor_z = 0.0, y_min = 0.0, y_max = 0.0, pixel = 0.0;
  std::size_t particles = 0;
  RunoutMeasure initial_length, final_length;  // from the back wall [m]
  HeightMeasure initial_height, final_height;  // from the floor [m]
  FlowRegime regime = FlowRegime::kStable;
  ReposeMeasure repose;  // of the final frame, as a heap around its highest point
  std::vector<double> initial_intensity, final_intensity;  // per pixel column
  std::vector<double> final_row_height;                    // per pixel row, from the floor
  std::vector<TimeSample> series;
  // Contact network of the initial frame (just before the gate opens).
  Histogram force_pdf_linear, force_pdf_log;
  Fabric fabric;
  // whole, half near the gate, quarter near the top of the gate (Table B.1), bulk
  std::vector<std::pair<std::string, Coordination>> coordination;
  double bulk_margin = 0.0;  // [m] the bulk region's inset (AnalysisOptions::bulk_margin)
  std::map<std::int64_t, WallLoad> wall_loads;
  std::vector<std::string> obstacle_names;  // by index, for the loads and contacts
  BranchFrame strong_network;

  double time_scale() const;      // tau_c = sqrt(H0 / g) [s]
  double velocity_scale() const;  // sqrt(g H0) [m/s]
  double gravity = 9.81;

  static constexpr std::size_t kBulkRegion = 3;  // index of "bulk" in `coordination`
  // The bulk region's coordination (empty when not measured).
  Coordination bulk() const {
    return coordination.size() > kBulkRegion ? coordination[kBulkRegion].second : Coordination{};
  }
};

RunAnalysis analyze_run(const RunOutput& run, const AnalysisOptions& options);

// Writes summary.csv (one row of scalars), runout.csv, height.csv,
// velocity.csv, force_pdf.csv, fabric.csv, coordination.csv, walls.csv and
// strong_network.vtp into `out` (created). Files are replaced atomically.
void write_analysis(const RunAnalysis& a, const std::filesystem::path& out);

// Several runs of one case (seeds): mean and standard deviation of the
// summary scalars (ensemble.csv) and the run-averaged force PDFs.
void write_ensemble(const std::vector<RunAnalysis>& runs, const std::filesystem::path& out);

// Column names and values of summary.csv, in order.
std::vector<std::pair<std::string, double>> summary_values(const RunAnalysis& a);

}  // namespace sanguis::dem::analysis
