#pragma once
// Conjugate gradients for the multigrid's bottom solves: the grid of blocks,
// gathered on every rank (multigrid.cpp on uniform forests, the graph of
// leaves in multigrid_composite.cpp). The operator is symmetric positive
// (semi-)definite, applied by apply(x, ax); project(r) removes the null-space
// component of the residual of a singular problem (a no-op otherwise). Starts
// from zero; stops when |r|^2 <= 1e-26 |rhs|^2, or after 4 n + 50 iterations.
#include <cstddef>
#include <vector>

namespace sanguis::flow {

template <typename Apply, typename Project>
std::vector<double> conjugate_gradients(const std::vector<double>& rhs, Apply&& apply,
                                        Project&& project) {
  const std::size_t cells = rhs.size();
  const auto dot = [](const std::vector<double>& a, const std::vector<double>& b) {
    double s = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
    return s;
  };
  std::vector<double> x(cells, 0.0), r = rhs, p = rhs, ap(cells, 0.0);
  const double bb = dot(rhs, rhs);
  double rr = bb;
  for (int it = 0; it < 4 * static_cast<int>(cells) + 50 && rr > 1e-26 * bb && bb > 0.0; ++it) {
    apply(p, ap);
    const double pap = dot(p, ap);
    if (!(pap > 0.0)) break;
    const double a = rr / pap;
    for (std::size_t i = 0; i < cells; ++i) {
      x[i] += a * p[i];
      r[i] -= a * ap[i];
    }
    project(r);
    const double rr_new = dot(r, r);
    if (rr_new == 0.0) break;
    for (std::size_t i = 0; i < cells; ++i) p[i] = r[i] + (rr_new / rr) * p[i];
    rr = rr_new;
  }
  return x;
}

}  // namespace sanguis::flow
