#pragma once
// Top view of a granular deposit, as the thesis' image processing sees it
// (§3.2.3, Fig. 3.2): particles are projected on the horizontal (x, y) plane
// into square pixels; a pixel is "white" when a particle covers it, and it
// keeps the highest point of the particles above it.
//
// Conventions: x is the flow direction (the channel runs from the back wall
// at x = wall towards +x), y the width of the channel, z the vertical.
#include <cstddef>
#include <utility>
#include <vector>

#include "core/vec3.hpp"
#include "dem/analysis/run_output.hpp"

namespace sanguis::dem::analysis {

class TopViewRaster {
 public:
  // Pixels of size `pixel` covering [x_min, x_max] x [y_min, y_max].
  TopViewRaster(double x_min, double x_max, double y_min, double y_max, double pixel);

  // A sphere: the disk of radius r around (c.x, c.y); the height over a pixel
  // centre is the top of the sphere there.
  void add_sphere(const Vec3& c, double r);
  // A surface triangle (bodies): covers the pixels whose centres fall inside
  // its projection, with the height interpolated linearly.
  void add_triangle(const Vec3& a, const Vec3& b, const Vec3& c);
  // Every particle of a frame: spheres as disks, bodies by their surface triangles.
  void add_frame(const ParticleFrame& particles, const BodySurfaceFrame& bodies);

  std::size_t nx() const { return nx_; }
  std::size_t ny() const { return ny_; }
  double pixel() const { return pixel_; }
  double x_min() const { return x_min_; }
  bool covered(std::size_t i, std::size_t j) const { return top_[j * nx_ + i] > kEmpty; }
  double top(std::size_t i, std::size_t j) const { return top_[j * nx_ + i]; }

  // Fraction of covered pixels in each x column (the column intensity of Fig. 3.2a).
  std::vector<double> column_intensity() const;
  // For each row j (position across the width), the highest point over x (Fig. 3.2b).
  std::vector<double> row_max_height() const;

  static constexpr double kEmpty = -1e300;

 private:
  std::pair<long, long> pixel_span(double lo, double hi, double origin, std::size_t n) const;

  double x_min_, y_min_, pixel_;
  std::size_t nx_, ny_;
  std::vector<double> top_;  // highest z over each pixel, kEmpty if uncovered
};

// Run-out distance L: from the back wall, the leading edge of the first
// pixel column whose intensity is below `threshold` (10% in the thesis, with
// 20% and 1% for the error bars), measured from the raster's x_min (the wall).
double runout_distance(const TopViewRaster& raster, double threshold);

struct RunoutMeasure {
  double length = 0.0;        // 10% threshold [m]
  double length_lower = 0.0;  // 20% threshold
  double length_upper = 0.0;  // 1% threshold
};
RunoutMeasure measure_runout(const TopViewRaster& raster);

// Pile height H: the mean over the width of the highest point of the pile,
// with the first and third quartiles (Fig. 3.2b); heights from z = floor.
struct HeightMeasure {
  double mean = 0.0;
  double first_quartile = 0.0;
  double third_quartile = 0.0;
};
HeightMeasure measure_height(const TopViewRaster& raster, double floor);

// Angle of repose of a heap (degrees), read two ways over the part between 20%
// and 80% of the heap height (the rounded top and the scattered foot excluded):
// - angle_deg: the surface envelope, the highest point in rings of width 2 pixels
//   around the apex (the centroid of the pixels within 5% of the highest), fitted
//   by a straight line;
// - cone_angle_deg: a cone r = a - h / tan(angle) fitted by least squares through
//   every covered pixel of the band, r from the centroid of the cap above the band
//   (the pixels above 80%): the mean radius of the heap's contour at each height.
//   It reads a mean slope over all azimuths, where the envelope reads the highest
//   profile at each radius (the shallowest slope), so on a heap that is not a cone
//   the two differ, and their gap says by how much. A deposit whose radii the cone
//   explains less than half of (cone_r_squared < 0.5: a layer spread flat) gets
//   cone_angle_deg = 0.
// Both give the slope of a cone of spheres (tests/dem/test_top_view.cpp). Suited
// to a conical heap on a floor (hopper, pouring).
struct ReposeMeasure {
  double angle_deg = 0.0;
  double cone_angle_deg = 0.0;
  double apex_height = 0.0;  // from the floor [m]
  std::size_t fitted_rings = 0;
  std::size_t cone_pixels = 0;  // pixels in the cone's fit
  double cone_r_squared = 0.0;  // share of the radii's variance the cone explains
};
ReposeMeasure measure_repose_angle(const TopViewRaster& raster, double floor);

// Quantile of a sample by linear interpolation between order statistics (q in [0, 1]).
double quantile(std::vector<double> values, double q);

}  // namespace sanguis::dem::analysis
