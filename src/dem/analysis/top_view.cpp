#include "dem/analysis/top_view.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sanguis::dem::analysis {

TopViewRaster::TopViewRaster(double x_min, double x_max, double y_min, double y_max, double pixel)
    : x_min_(x_min), y_min_(y_min), pixel_(pixel) {
  if (!(pixel > 0) || !(x_max > x_min) || !(y_max > y_min)) {
    throw std::invalid_argument("top view: empty extent or non-positive pixel size");
  }
  nx_ = static_cast<std::size_t>(std::ceil((x_max - x_min) / pixel));
  ny_ = static_cast<std::size_t>(std::ceil((y_max - y_min) / pixel));
  top_.assign(nx_ * ny_, kEmpty);
}

// Pixels whose centres lie in [lo, hi] along one axis, clipped to [0, n).
std::pair<long, long> TopViewRaster::pixel_span(double lo, double hi, double origin,
                                                std::size_t n) const {
  const long first = static_cast<long>(std::ceil((lo - origin) / pixel_ - 0.5));
  const long last = static_cast<long>(std::floor((hi - origin) / pixel_ - 0.5));
  return {std::max(0L, first), std::min(static_cast<long>(n) - 1, last)};
}

void TopViewRaster::add_sphere(const Vec3& c, double r) {
  const auto [i0, i1] = pixel_span(c.x - r, c.x + r, x_min_, nx_);
  const auto [j0, j1] = pixel_span(c.y - r, c.y + r, y_min_, ny_);
  for (long j = j0; j <= j1; ++j) {
    const double dy = y_min_ + (static_cast<double>(j) + 0.5) * pixel_ - c.y;
    for (long i = i0; i <= i1; ++i) {
      const double dx = x_min_ + (static_cast<double>(i) + 0.5) * pixel_ - c.x;
      const double h2 = r * r - dx * dx - dy * dy;
      if (h2 < 0) continue;
      double& top = top_[static_cast<std::size_t>(j) * nx_ + static_cast<std::size_t>(i)];
      top = std::max(top, c.z + std::sqrt(h2));
    }
  }
}

void TopViewRaster::add_triangle(const Vec3& a, const Vec3& b, const Vec3& c) {
  const double area2 = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
  if (std::abs(area2) < 1e-300) return;  // seen edge-on: its edges are covered by neighbours
  const double xlo = std::min({a.x, b.x, c.x}), xhi = std::max({a.x, b.x, c.x});
  const double ylo = std::min({a.y, b.y, c.y}), yhi = std::max({a.y, b.y, c.y});
  const auto [i0, i1] = pixel_span(xlo, xhi, x_min_, nx_);
  const auto [j0, j1] = pixel_span(ylo, yhi, y_min_, ny_);
  for (long j = j0; j <= j1; ++j) {
    const double py = y_min_ + (static_cast<double>(j) + 0.5) * pixel_;
    for (long i = i0; i <= i1; ++i) {
      const double px = x_min_ + (static_cast<double>(i) + 0.5) * pixel_;
      // Barycentric coordinates of the pixel centre.
      const double wb = ((px - a.x) * (c.y - a.y) - (c.x - a.x) * (py - a.y)) / area2;
      const double wc = ((b.x - a.x) * (py - a.y) - (px - a.x) * (b.y - a.y)) / area2;
      const double wa = 1.0 - wb - wc;
      if (wa < 0 || wb < 0 || wc < 0) continue;
      double& top = top_[static_cast<std::size_t>(j) * nx_ + static_cast<std::size_t>(i)];
      top = std::max(top, wa * a.z + wb * b.z + wc * c.z);
    }
  }
}

void TopViewRaster::add_frame(const ParticleFrame& particles, const BodySurfaceFrame& bodies) {
  for (std::size_t k = 0; k < particles.size(); ++k) {
    if (particles.spherical.empty() || particles.spherical[k] != 0) {
      add_sphere(particles.position[k], particles.radius[k]);
    }
  }
  for (std::size_t t = 0; t < bodies.size(); ++t)
    add_triangle(bodies.a[t], bodies.b[t], bodies.c[t]);
}

std::vector<double> TopViewRaster::column_intensity() const {
  std::vector<double> intensity(nx_, 0.0);
  for (std::size_t j = 0; j < ny_; ++j) {
    for (std::size_t i = 0; i < nx_; ++i) intensity[i] += covered(i, j) ? 1.0 : 0.0;
  }
  for (double& v : intensity) v /= static_cast<double>(ny_);
  return intensity;
}

std::vector<double> TopViewRaster::row_max_height() const {
  std::vector<double> height(ny_, kEmpty);
  for (std::size_t j = 0; j < ny_; ++j) {
    for (std::size_t i = 0; i < nx_; ++i) height[j] = std::max(height[j], top(i, j));
  }
  return height;
}

double runout_distance(const TopViewRaster& raster, double threshold) {
  const std::vector<double> intensity = raster.column_intensity();
  for (std::size_t i = 0; i < intensity.size(); ++i) {
    if (intensity[i] < threshold) return static_cast<double>(i) * raster.pixel();
  }
  return static_cast<double>(intensity.size()) * raster.pixel();
}

RunoutMeasure measure_runout(const TopViewRaster& raster) {
  return {runout_distance(raster, 0.10), runout_distance(raster, 0.20),
          runout_distance(raster, 0.01)};
}

namespace {

// Least-squares straight line y = a + b x through (x, y) pairs, accumulated.
struct LineFit {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
  void add(double x, double y) {
    n += 1;
    sx += x;
    sy += y;
    sxx += x * x;
    sxy += x * y;
    syy += y * y;
  }
  double slope() const { return (n * sxy - sx * sy) / (n * sxx - sx * sx); }
  // Share of the variance of y that the line explains (the squared correlation).
  double r_squared() const {
    const double cov = n * sxy - sx * sy;
    return cov * cov / ((n * sxx - sx * sx) * (n * syy - sy * sy));
  }
};

constexpr double kDegrees = 180.0 / 3.14159265358979323846;
constexpr double kConeMinRSquared = 0.5;

// Angle below the horizontal of a fit of height against radius.
double slope_angle_deg(const LineFit& height_on_radius) {
  return std::atan(std::max(0.0, -height_on_radius.slope())) * kDegrees;
}

// Centroid (in pixel indices) of the pixels higher than `fraction` of the heap.
std::pair<double, double> centroid_above(const TopViewRaster& raster, double floor, double height,
                                         double fraction) {
  double ax = 0.0, ay = 0.0, weight = 0.0;
  for (std::size_t j = 0; j < raster.ny(); ++j) {
    for (std::size_t i = 0; i < raster.nx(); ++i) {
      if (raster.top(i, j) - floor < fraction * height) continue;
      ax += static_cast<double>(i);
      ay += static_cast<double>(j);
      weight += 1.0;
    }
  }
  return {ax / weight, ay / weight};
}

}  // namespace

ReposeMeasure measure_repose_angle(const TopViewRaster& raster, double floor) {
  double highest = TopViewRaster::kEmpty;
  for (std::size_t j = 0; j < raster.ny(); ++j) {
    for (std::size_t i = 0; i < raster.nx(); ++i) highest = std::max(highest, raster.top(i, j));
  }
  ReposeMeasure m;
  if (highest <= floor) return m;
  const double height = highest - floor;
  m.apex_height = height;
  const auto in_band = [&](double h) { return h >= 0.2 * height && h <= 0.8 * height; };
  const auto radius = [&](std::size_t i, std::size_t j, std::pair<double, double> c) {
    return raster.pixel() *
           std::hypot(static_cast<double>(i) - c.first, static_cast<double>(j) - c.second);
  };

  const auto apex = centroid_above(raster, floor, height, 0.95);
  const double ring = 2.0 * raster.pixel();
  std::vector<double> envelope;
  for (std::size_t j = 0; j < raster.ny(); ++j) {
    for (std::size_t i = 0; i < raster.nx(); ++i) {
      if (!raster.covered(i, j)) continue;
      const auto k = static_cast<std::size_t>(radius(i, j, apex) / ring);
      if (k >= envelope.size()) envelope.resize(k + 1, 0.0);
      envelope[k] = std::max(envelope[k], raster.top(i, j) - floor);
    }
  }
  LineFit rings;
  for (std::size_t k = 0; k < envelope.size(); ++k) {
    if (in_band(envelope[k])) rings.add((static_cast<double>(k) + 0.5) * ring, envelope[k]);
  }
  m.fitted_rings = static_cast<std::size_t>(rings.n);
  if (rings.n >= 2) m.angle_deg = slope_angle_deg(rings);

  // Radius against height, not height against radius: the band selects on the
  // height, and a least-squares fit whose dependent variable is truncated is biased
  // towards a flat line (a heap whose slope varies with the azimuth read below its
  // shallowest slope). With the height as the regressor, the fit gives the mean
  // radius of the heap's contour at each height.
  const auto cap = centroid_above(raster, floor, height, 0.8);
  LineFit surface;
  for (std::size_t j = 0; j < raster.ny(); ++j) {
    for (std::size_t i = 0; i < raster.nx(); ++i) {
      const double h = raster.top(i, j) - floor;
      if (raster.covered(i, j) && in_band(h)) surface.add(h, radius(i, j, cap));
    }
  }
  // A deposit spread flat has no relation between height and radius (the fit's
  // slope then tends to zero and the angle to 90°): below half the radii's variance
  // explained it is not a cone, and gets no angle (the hopper's heaps explain
  // 0.72-0.83, its flat layers 0-0.22).
  m.cone_pixels = static_cast<std::size_t>(surface.n);
  if (surface.n >= 2) m.cone_r_squared = surface.r_squared();
  if (surface.n >= 2 && m.cone_r_squared >= kConeMinRSquared && surface.slope() < 0.0) {
    m.cone_angle_deg = std::atan(-1.0 / surface.slope()) * kDegrees;
  }
  return m;
}

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const double at = q * static_cast<double>(values.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(at));
  const std::size_t hi = std::min(lo + 1, values.size() - 1);
  return values[lo] + (at - static_cast<double>(lo)) * (values[hi] - values[lo]);
}

HeightMeasure measure_height(const TopViewRaster& raster, double floor) {
  std::vector<double> heights;
  for (const double h : raster.row_max_height()) {
    heights.push_back(h > TopViewRaster::kEmpty ? h - floor : 0.0);
  }
  double sum = 0.0;
  for (const double h : heights) sum += h;
  HeightMeasure m;
  m.mean = heights.empty() ? 0.0 : sum / static_cast<double>(heights.size());
  m.first_quartile = quantile(heights, 0.25);
  m.third_quartile = quantile(heights, 0.75);
  return m;
}

}  // namespace sanguis::dem::analysis
