#include "dem/analysis/analyze.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <ostream>
#include <stdexcept>

#include "core/io/atomic_file.hpp"
#include "core/io/vtk.hpp"

namespace sanguis::dem::analysis {
namespace {

struct Extent {
  double x_min = std::numeric_limits<double>::infinity(), x_max = -x_min;
  double y_min = x_min, y_max = -x_min, z_min = x_min;
  double mean_radius = 0.0;
  double pixel = 0.0;  // default pixel size
};

// Extent of what a top view sees: spheres by their radius, bodies by their
// surface triangles (their bounding radius would reach through the walls).
Extent extent_of(const ParticleFrame& p, const BodySurfaceFrame& bodies) {
  Extent e;
  const auto include = [&](const Vec3& lo, const Vec3& hi) {
    e.x_min = std::min(e.x_min, lo.x);
    e.x_max = std::max(e.x_max, hi.x);
    e.y_min = std::min(e.y_min, lo.y);
    e.y_max = std::max(e.y_max, hi.y);
    e.z_min = std::min(e.z_min, lo.z);
  };
  bool any_body = false;
  for (std::size_t k = 0; k < p.size(); ++k) {
    const double r = p.radius[k];
    e.mean_radius += r;
    if (!p.spherical.empty() && p.spherical[k] == 0) {
      any_body = true;
      continue;
    }
    include(p.position[k] - Vec3{r, r, r}, p.position[k] + Vec3{r, r, r});
  }
  for (std::size_t t = 0; t < bodies.size(); ++t) {
    for (const Vec3& v : {bodies.a[t], bodies.b[t], bodies.c[t]}) include(v, v);
  }
  if (p.size() > 0) e.mean_radius /= static_cast<double>(p.size());
  // Pixels resolve a sphere with a few across its radius; a body's arms are much
  // thinner than its bounding radius (a cross: 2 mm arms, 13.5 mm radius).
  e.pixel = (any_body ? 0.1 : 0.5) * e.mean_radius;
  return e;
}

TopViewRaster top_view(const ParticleFrame& particles, const BodySurfaceFrame& bodies,
                       const RunAnalysis& a) {
  // Long enough for any run-out: up to the farthest particle of this frame.
  const Extent e = extent_of(particles, bodies);
  TopViewRaster raster(a.wall_x, std::max(e.x_max, a.wall_x + a.pixel) + a.pixel, a.y_min, a.y_max,
                       a.pixel);
  raster.add_frame(particles, bodies);
  return raster;
}

std::string format(double v) {
  std::array<char, 32> text{};
  std::snprintf(text.data(), text.size(), "%.10g", v);
  return text.data();
}

void write_csv(const std::filesystem::path& path, const std::vector<std::string>& header,
               const std::vector<std::vector<std::string>>& rows) {
  io::write_file_atomically(path, [&](std::ostream& out) {
    for (std::size_t c = 0; c < header.size(); ++c) out << (c ? "," : "") << header[c];
    out << "\n";
    for (const auto& row : rows) {
      for (std::size_t c = 0; c < row.size(); ++c) out << (c ? "," : "") << row[c];
      out << "\n";
    }
  });
}

std::vector<std::vector<std::string>> histogram_rows(const Histogram& h, const std::string& kind) {
  std::vector<std::vector<std::string>> rows;
  for (std::size_t b = 0; b < h.counts.size(); ++b) {
    rows.push_back({kind, format(h.edges[b]), format(h.edges[b + 1]),
                    format(0.5 * (h.edges[b] + h.edges[b + 1])), format(h.counts[b]),
                    format(h.density[b])});
  }
  return rows;
}

std::string quoted(const std::string& s) {
  std::string q = "\"";
  for (const char c : s) q += (c == '"') ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

}  // namespace

double RunAnalysis::time_scale() const {
  return std::sqrt(initial_height.mean / gravity);
}
double RunAnalysis::velocity_scale() const {
  return std::sqrt(gravity * initial_height.mean);
}

RunAnalysis analyze_run(const RunOutput& run, const AnalysisOptions& o) {
  RunAnalysis a;
  a.run = run.dir().string();
  a.gravity = o.gravity;
  const std::optional<double> gate_time =
      o.initial_time ? o.initial_time : run.first_removal_time();
  std::size_t first = gate_time ? run.frame_at(*gate_time) : 0;
  const std::size_t last = run.frame_at(o.final_time);
  if (last < first) throw std::runtime_error("the final frame comes before the initial frame");
  ParticleFrame initial = run.particles(first);
  while (initial.size() == 0 && first < last) initial = run.particles(++first);  // pouring
  const ParticleFrame final = run.particles(last);
  if (initial.size() == 0) {
    throw std::runtime_error(run.dir().string() + ": the initial frame (t = " +
                             format(initial.time) + " s) has no particles");
  }
  a.initial_time = initial.time;
  // The frame before the removal gives L0 and H0; the clock starts at the removal itself
  // (frames fall on the output grid, up to one interval earlier).
  a.release_time = gate_time && *gate_time >= initial.time ? *gate_time : initial.time;
  a.final_time = final.time;
  a.particles = final.size();

  // The union of both frames' extents: a dam break keeps its back wall and
  // width, a heap spreads from its pouring region.
  const BodySurfaceFrame initial_bodies = run.bodies(first), final_bodies = run.bodies(last);
  const Extent e0 = extent_of(initial, initial_bodies), e1 = extent_of(final, final_bodies);
  a.wall_x = o.wall_x.value_or(std::min(e0.x_min, e1.x_min));
  a.floor_z = o.floor_z.value_or(std::min(e0.z_min, e1.z_min));
  a.y_min = o.y_min.value_or(std::min(e0.y_min, e1.y_min));
  a.y_max = o.y_max.value_or(std::max(e0.y_max, e1.y_max));
  a.pixel = o.pixel.value_or(e0.pixel);

  const TopViewRaster before = top_view(initial, initial_bodies, a);
  const TopViewRaster after = top_view(final, final_bodies, a);
  a.initial_length = measure_runout(before);
  a.final_length = measure_runout(after);
  a.initial_height = measure_height(before, a.floor_z);
  a.final_height = measure_height(after, a.floor_z);
  a.initial_intensity = before.column_intensity();
  a.final_intensity = after.column_intensity();
  for (const double h : after.row_max_height()) {
    a.final_row_height.push_back(h > TopViewRaster::kEmpty ? h - a.floor_z : 0.0);
  }
  a.repose = measure_repose_angle(after, a.floor_z);
  a.regime = classify_regime(a.initial_height.mean, a.final_height.mean, a.initial_length.length,
                             a.final_length.length, o.regime);

  for (std::size_t f = first; f <= last; ++f) {
    const ParticleFrame p = f == first ? initial : (f == last ? final : run.particles(f));
    a.series.push_back({p.time, mean_speed(p), centre_of_mass(p)});
  }

  // The contact network just before the gate opens.
  const BranchFrame branches = run.branches(first);
  const ContactPointFrame contacts = run.contacts(first);
  const std::vector<double> scaled = scaled_force_magnitudes(branches);
  a.force_pdf_linear = histogram(scaled, linear_edges(0.0, 6.0, 30));
  a.force_pdf_log = histogram(scaled, log_edges(1e-3, 1e2, 30));
  a.fabric = fabric_xz(branches, o.fabric_bins);
  const double x_gate = a.wall_x + a.initial_length.length;
  const double x_half = a.wall_x + 0.5 * a.initial_length.length;
  const double z_half = a.floor_z + 0.5 * a.initial_height.mean;
  Region whole, gate_half, gate_top;
  gate_half.min.x = x_half;
  gate_half.max.x = x_gate;
  gate_top = gate_half;
  gate_top.min.z = z_half;
  const double margin = o.bulk_margin.value_or(4.0 * e0.mean_radius);
  Region bulk;
  bulk.min = {a.wall_x + margin, a.y_min + margin, a.floor_z + margin};
  bulk.max = {x_gate - margin, a.y_max - margin, a.floor_z + a.initial_height.mean - margin};
  a.bulk_margin = margin;
  a.coordination = {
      {"whole", coordination(initial, branches, contacts, whole)},
      {"half near the gate", coordination(initial, branches, contacts, gate_half)},
      {"quarter near the top of the gate", coordination(initial, branches, contacts, gate_top)},
      {"bulk", coordination(initial, branches, contacts, bulk)}};
  a.wall_loads = wall_loads(initial, contacts, o.gravity);
  for (std::size_t k = 0; k < std::max<std::size_t>(run.obstacle_count(), 1); ++k) {
    a.obstacle_names.push_back(run.obstacle_name(static_cast<std::int64_t>(k)));
  }
  for (const auto& [index, load] : a.wall_loads) {
    while (a.obstacle_names.size() <= static_cast<std::size_t>(index)) {
      a.obstacle_names.push_back(
          run.obstacle_name(static_cast<std::int64_t>(a.obstacle_names.size())));
    }
  }
  for (std::size_t k = 0; k < branches.size(); ++k) {
    if (scaled[k] < o.strong_force_ratio) continue;
    a.strong_network.from.push_back(branches.from[k]);
    a.strong_network.to.push_back(branches.to[k]);
    a.strong_network.force_magnitude.push_back(branches.force_magnitude[k]);
    a.strong_network.first.push_back(branches.first[k]);
    a.strong_network.second.push_back(branches.second[k]);
  }
  return a;
}

std::vector<std::pair<std::string, double>> summary_values(const RunAnalysis& a) {
  const Vec3 c0 = a.series.empty() ? Vec3{} : a.series.front().centre_of_mass;
  const Vec3 c1 = a.series.empty() ? Vec3{} : a.series.back().centre_of_mass;
  const double l0 = a.initial_length.length, h0 = a.initial_height.mean;
  double peak_speed = 0.0, peak_time = a.release_time;
  for (const TimeSample& s : a.series) {
    if (s.mean_speed > peak_speed) {
      peak_speed = s.mean_speed;
      peak_time = s.time;
    }
  }
  const Coordination whole = a.coordination.empty() ? Coordination{} : a.coordination[0].second;
  const Coordination bulk = a.bulk();
  // Staggered collapses (Fig. 3.10) on the non-dimensional curve of velocity.csv.
  Halts halts;
  if (h0 > 0) {
    std::vector<double> t, v;
    for (const TimeSample& s : a.series) {
      t.push_back((s.time - a.release_time) / a.time_scale());
      v.push_back(s.mean_speed / a.velocity_scale());
    }
    halts = find_halts(t, v);
  }
  return {
      {"initial_time_s", a.initial_time},
      {"release_time_s", a.release_time},
      {"final_time_s", a.final_time},
      {"particles", static_cast<double>(a.particles)},
      {"L0_m", l0},
      {"H0_m", h0},
      {"H0_q1_m", a.initial_height.first_quartile},
      {"H0_q3_m", a.initial_height.third_quartile},
      {"aspect_ratio_H0_over_L0", l0 > 0 ? h0 / l0 : 0.0},
      {"Linf_m", a.final_length.length},
      {"Linf_20pc_m", a.final_length.length_lower},
      {"Linf_1pc_m", a.final_length.length_upper},
      {"Hinf_m", a.final_height.mean},
      {"Hinf_q1_m", a.final_height.first_quartile},
      {"Hinf_q3_m", a.final_height.third_quartile},
      {"runout_ratio", l0 > 0 ? (a.final_length.length - l0) / l0 : 0.0},
      {"height_ratio_H0_over_Hinf", a.final_height.mean > 0 ? h0 / a.final_height.mean : 0.0},
      {"regime", static_cast<double>(a.regime)},
      {"com_displacement_x_m", c1.x - c0.x},
      {"com_displacement_x_over_L0", l0 > 0 ? (c1.x - c0.x) / l0 : 0.0},
      {"peak_mean_speed_over_sqrt_gH0", h0 > 0 ? peak_speed / a.velocity_scale() : 0.0},
      {"peak_time_over_tau_c", h0 > 0 ? (peak_time - a.release_time) / a.time_scale() : 0.0},
      {"halts", static_cast<double>(halts.count)},
      {"longest_halt_over_tau_c", halts.longest},
      {"pair_coordination", whole.pair_coordination},
      {"contact_point_coordination", whole.contact_point_coordination},
      {"fabric_anisotropy", a.fabric.anisotropy},
      {"repose_angle_deg", a.repose.angle_deg},
      {"repose_cone_angle_deg", a.repose.cone_angle_deg},
      {"repose_cone_r_squared", a.repose.cone_r_squared},
      {"fabric_principal_angle_deg", a.fabric.principal_angle_deg},
      {"particles_touching_obstacles_fraction",
       whole.particles > 0 ? static_cast<double>(whole.particles_touching_obstacles) /
                                 static_cast<double>(whole.particles)
                           : 0.0},
      {"pair_coordination_away_from_obstacles", whole.pair_coordination_away_from_obstacles},
      {"bulk_margin_m", a.bulk_margin},
      {"bulk_particles", static_cast<double>(bulk.particles)},
      {"bulk_pair_coordination", bulk.pair_coordination},
      {"bulk_contact_point_coordination", bulk.contact_point_coordination},
  };
}

void write_analysis(const RunAnalysis& a, const std::filesystem::path& out) {
  std::filesystem::create_directories(out);
  const auto summary = summary_values(a);
  std::vector<std::string> header, values;
  for (const auto& [name, value] : summary) {
    header.push_back(name);
    values.push_back(format(value));
  }
  write_csv(out / "summary.csv", header, {values});

  std::vector<std::vector<std::string>> rows;
  const std::size_t columns = std::max(a.initial_intensity.size(), a.final_intensity.size());
  for (std::size_t i = 0; i < columns; ++i) {
    const auto at = [&](const std::vector<double>& v) { return i < v.size() ? v[i] : 0.0; };
    rows.push_back({format((static_cast<double>(i) + 0.5) * a.pixel),
                    format(at(a.initial_intensity)), format(at(a.final_intensity))});
  }
  write_csv(out / "runout.csv", {"x_from_wall_m", "initial_intensity", "final_intensity"}, rows);

  rows.clear();
  for (std::size_t j = 0; j < a.final_row_height.size(); ++j) {
    rows.push_back({format(a.y_min + (static_cast<double>(j) + 0.5) * a.pixel),
                    format(a.final_row_height[j])});
  }
  write_csv(out / "height.csv", {"y_m", "final_height_m"}, rows);

  rows.clear();
  for (const TimeSample& s : a.series) {
    const double t = s.time - a.release_time;
    rows.push_back({format(s.time), format(t / a.time_scale()), format(s.mean_speed),
                    format(s.mean_speed / a.velocity_scale()), format(s.centre_of_mass.x),
                    format(s.centre_of_mass.y), format(s.centre_of_mass.z)});
  }
  write_csv(out / "velocity.csv",
            {"time_s", "time_over_tau_c", "mean_speed_m_s", "mean_speed_over_sqrt_gH0", "com_x_m",
             "com_y_m", "com_z_m"},
            rows);

  rows = histogram_rows(a.force_pdf_linear, "linear");
  for (auto& r : histogram_rows(a.force_pdf_log, "log")) rows.push_back(std::move(r));
  write_csv(out / "force_pdf.csv", {"bins", "lower", "upper", "centre", "count", "pdf"}, rows);

  write_csv(out / "fabric.csv", {"bins", "lower_deg", "upper_deg", "centre_deg", "count", "pdf"},
            histogram_rows(a.fabric.angles, "angle"));

  rows.clear();
  for (const auto& [name, c] : a.coordination) {
    std::vector<std::string> row = {quoted(name),
                                    format(static_cast<double>(c.particles)),
                                    format(c.pair_coordination),
                                    format(c.contact_point_coordination),
                                    format(static_cast<double>(c.particles_touching_obstacles)),
                                    format(c.pair_coordination_away_from_obstacles)};
    rows.push_back(row);
  }
  write_csv(out / "coordination.csv",
            {"region", "particles", "pair_coordination", "contact_point_coordination",
             "particles_touching_obstacles", "pair_coordination_away_from_obstacles"},
            rows);

  // Contacts per obstacle, by region, and the loads of the whole assembly.
  rows.clear();
  for (std::size_t k = 0; k < a.obstacle_names.size(); ++k) {
    const auto index = static_cast<std::int64_t>(k);
    std::vector<std::string> row = {format(static_cast<double>(k)), quoted(a.obstacle_names[k])};
    for (const auto& [name, c] : a.coordination) {
      const auto it = c.wall_contact_points.find(index);
      row.push_back(
          format(it == c.wall_contact_points.end() ? 0.0 : static_cast<double>(it->second)));
    }
    const auto load = a.wall_loads.find(index);
    const WallLoad w = load == a.wall_loads.end() ? WallLoad{} : load->second;
    for (const double v : {w.force.x, w.force.y, w.force.z, w.weight_fraction}) {
      row.push_back(format(v));
    }
    rows.push_back(row);
  }
  write_csv(out / "walls.csv",
            {"obstacle", "name", "contacts_whole", "contacts_half_near_gate",
             "contacts_quarter_near_gate_top", "contacts_bulk", "force_x_N", "force_y_N",
             "force_z_N", "weight_fraction"},
            rows);

  io::PolyMesh network;
  io::DataArray magnitude{"force_magnitude", 1, {}};
  io::IntDataArray first{"first_id", 1, {}}, second{"second_id", 1, {}};
  for (std::size_t k = 0; k < a.strong_network.size(); ++k) {
    const auto base = static_cast<std::int64_t>(network.points.size());
    network.points.push_back(a.strong_network.from[k]);
    network.points.push_back(a.strong_network.to[k]);
    network.lines.push_back({base, base + 1});
    magnitude.values.push_back(a.strong_network.force_magnitude[k]);
    first.values.push_back(a.strong_network.first[k]);
    second.values.push_back(a.strong_network.second[k]);
  }
  network.cell_data = {std::move(magnitude)};
  network.int_cell_data = {std::move(first), std::move(second)};
  io::write_polymesh_vtp(out / "strong_network.vtp", network);
}

void write_ensemble(const std::vector<RunAnalysis>& runs, const std::filesystem::path& out) {
  if (runs.empty()) throw std::invalid_argument("ensemble: no run");
  std::filesystem::create_directories(out);
  std::vector<std::vector<std::pair<std::string, double>>> all;
  for (const RunAnalysis& r : runs) all.push_back(summary_values(r));
  // The bulk's coordination counts only in the runs that have a bulk: an empty
  // one reads 0, which measures nothing.
  const auto bulk_column = std::find_if(all[0].begin(), all[0].end(),
                                        [](const auto& v) { return v.first == "bulk_particles"; });
  if (bulk_column == all[0].end()) throw std::logic_error("ensemble: no bulk_particles column");
  const auto bulk_particles = static_cast<std::size_t>(bulk_column - all[0].begin());
  std::vector<std::vector<std::string>> rows;
  for (std::size_t c = 0; c < all[0].size(); ++c) {
    const std::string& name = all[0][c].first;
    const bool bulk_only =
        name == "bulk_pair_coordination" || name == "bulk_contact_point_coordination";
    std::vector<double> values;
    for (const auto& s : all) {
      if (!bulk_only || s[bulk_particles].second > 0) values.push_back(s[c].second);
    }
    if (values.empty()) {
      rows.push_back({name, "", "", "", "", "0"});
      continue;
    }
    double sum = 0.0, sum2 = 0.0, lo = values[0], hi = lo;
    for (const double v : values) {
      sum += v;
      sum2 += v * v;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    const double n = static_cast<double>(values.size());
    const double mean = sum / n;
    const double var = n > 1 ? std::max(0.0, (sum2 - n * mean * mean) / (n - 1)) : 0.0;
    rows.push_back({name, format(mean), format(std::sqrt(var)), format(lo), format(hi), format(n)});
  }
  std::size_t regimes[3] = {0, 0, 0};
  for (const RunAnalysis& r : runs) ++regimes[static_cast<int>(r.regime)];
  for (int k = 0; k < 3; ++k) {
    rows.push_back({"fraction_" + to_string(static_cast<FlowRegime>(k)),
                    format(static_cast<double>(regimes[k]) / static_cast<double>(runs.size())), "",
                    "", "", format(static_cast<double>(runs.size()))});
  }
  write_csv(out / "ensemble.csv", {"quantity", "mean", "std", "min", "max", "runs"}, rows);

  std::vector<Histogram> lin, log;
  for (const RunAnalysis& r : runs) {
    lin.push_back(r.force_pdf_linear);
    log.push_back(r.force_pdf_log);
  }
  std::vector<std::vector<std::string>> pdf = histogram_rows(average(lin), "linear");
  for (auto& r : histogram_rows(average(log), "log")) pdf.push_back(std::move(r));
  write_csv(out / "force_pdf.csv", {"bins", "lower", "upper", "centre", "count", "pdf"}, pdf);
}

}  // namespace sanguis::dem::analysis
