#include "geometry/predicates.hpp"

#include <vector>

namespace sanguis::geometry::detail {
namespace {

// A floating-point expansion: a sum of doubles that do not overlap, in order
// of increasing magnitude, representing a real number exactly (Shewchuk
// 1997, §2). Zero components are dropped as they appear.
using Expansion = std::vector<double>;

// a + b = x + y exactly, |y| <= ulp(x)/2 (Knuth's TwoSum).
void two_sum(double a, double b, double& x, double& y) {
  x = a + b;
  const double b_virtual = x - a;
  const double a_virtual = x - b_virtual;
  y = (a - a_virtual) + (b - b_virtual);
}

// a = high + low with both halves of at most 26 significant bits (Dekker).
void split(double a, double& high, double& low) {
  const double c = 134217729.0 * a;  // 2^27 + 1
  high = c - (c - a);
  low = a - high;
}

// a * b = x + y exactly (Dekker's TwoProduct, no fused multiply-add needed).
void two_product(double a, double b, double& x, double& y) {
  x = a * b;
  double ah, al, bh, bl;
  split(a, ah, al);
  split(b, bh, bl);
  y = al * bl - (((x - ah * bh) - al * bh) - ah * bl);
}

// e + b (Shewchuk's GROW-EXPANSION with zero elimination).
Expansion grow(const Expansion& e, double b) {
  Expansion h;
  h.reserve(e.size() + 1);
  double q = b;
  for (const double component : e) {
    double sum, error;
    two_sum(q, component, sum, error);
    if (error != 0.0) h.push_back(error);
    q = sum;
  }
  if (q != 0.0 || h.empty()) h.push_back(q);
  return h;
}

Expansion add(Expansion e, const Expansion& f) {
  for (const double component : f) e = grow(e, component);
  return e;
}

Expansion negate(Expansion e) {
  for (double& component : e) component = -component;
  return e;
}

Expansion multiply(const Expansion& e, const Expansion& f) {
  Expansion product{0.0};
  for (const double a : e)
    for (const double b : f) {
      double x, y;
      two_product(a, b, x, y);
      product = grow(grow(product, y), x);
    }
  return product;
}

Expansion difference(double a, double b) {
  double x, y;
  two_sum(a, -b, x, y);
  return y != 0.0 ? Expansion{y, x} : Expansion{x};
}

int sign(const Expansion& e) {
  for (auto it = e.rbegin(); it != e.rend(); ++it)
    if (*it != 0.0) return *it > 0.0 ? 1 : -1;
  return 0;
}

}  // namespace

int orientation_exact(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& p) {
  Expansion ab[3], ac[3], ap[3];
  for (int k = 0; k < 3; ++k) {
    ab[k] = difference(b[k], a[k]);
    ac[k] = difference(c[k], a[k]);
    ap[k] = difference(p[k], a[k]);
  }
  // det = ap . (ab x ac), component k of the cross product from axes k+1, k+2.
  Expansion det{0.0};
  for (int k = 0; k < 3; ++k) {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const Expansion cross_k = add(multiply(ab[i], ac[j]), negate(multiply(ab[j], ac[i])));
    det = add(det, multiply(ap[k], cross_k));
  }
  return sign(det);
}

}  // namespace sanguis::geometry::detail
