// Driver of the membrane bending validation (thesis §4.4.1, Fig. 4.3-4.4):
//   validate_membrane_bending OUTDIR
// writes OUTDIR/biconcave_5120.csv (one row per node: polar angle, numerical
// and exact kappa, kappa_g, Delta_s kappa, force density) and
// OUTDIR/convergence.csv (error norms vs refinement, sphere and biconcave
// cell). validation/membrane/bending.py plots them and writes the report.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "bending_errors.hpp"

using namespace sanguis;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: validate_membrane_bending OUTDIR\n";
    return 2;
  }
  const std::filesystem::path out_dir = argv[1];
  std::filesystem::create_directories(out_dir);
  const membrane::BiconcaveShape rbc{1.0, 0.207, 2.003, -1.123};
  {
    std::ofstream csv(out_dir / "biconcave_5120.csv");
    csv.precision(12);
    csv << "theta,kappa,kappa_exact,kappa_g,kappa_g_exact,laplace,laplace_exact,force,force_"
           "exact\n";
    for (const auto& c : validation::compare_biconcave(4, rbc))
      csv << c.theta << ',' << c.kappa << ',' << c.kappa_exact << ',' << c.kappa_g << ','
          << c.kappa_g_exact << ',' << c.laplace << ',' << c.laplace_exact << ',' << c.force << ','
          << c.force_exact << '\n';
  }
  std::ofstream csv(out_dir / "convergence.csv");
  csv.precision(6);
  csv << "shape,triangles,kappa_l2,kappa_linf,kappa_g_l2,kappa_g_linf,laplace_l2,laplace_linf,"
         "force_l2,force_linf\n";
  const auto row = [&](const char* shape, int k, const validation::BendingErrors& e) {
    csv << shape << ',' << 20 * (1 << (2 * k)) << ',' << e.kappa.l2 << ',' << e.kappa.linf << ','
        << e.kappa_g.l2 << ',' << e.kappa_g.linf << ',' << e.laplace.l2 << ',' << e.laplace.linf
        << ',' << e.force.l2 << ',' << e.force.linf << '\n';
  };
  for (int k = 2; k <= 5; ++k) {
    // Sphere R = 1 with kappa0 = 0.5: exact force density 4 kappa0 (1 - kappa0) = 1.
    row("sphere", k, validation::errors(validation::compare_sphere(k, 1.0, 0.5), 1.0, 1.0, 1.0));
    row("biconcave", k, validation::errors(validation::compare_biconcave(k, rbc), 0.0, 0.0, 0.0));
  }
  std::cout << "wrote " << (out_dir / "biconcave_5120.csv") << " and "
            << (out_dir / "convergence.csv") << '\n';
  return 0;
}
