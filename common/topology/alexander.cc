#include "topology/alexander.h"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <optional>
#include <utility>

namespace snapthread::topology {
namespace {

// __extension__: -Wpedantic rejects __int128 by name otherwise.
__extension__ typedef __int128 Int;
__extension__ typedef unsigned __int128 UInt;
using Poly = std::vector<Int>;  // coefficients from t^0 up, no trailing zeros

// One matrix entry a + b t.
struct Linear {
  std::int64_t a = 0, b = 0;
};

struct Event {
  int edge;
  double param;
  int crossing;
  bool under;
};

// The struck Alexander matrix, N-1 square, entries linear in t.
std::vector<std::vector<Linear>> AlexanderMatrix(const Diagram& d) {
  const int n = static_cast<int>(d.crossings.size());
  std::vector<Event> events;
  events.reserve(2 * n);
  for (int c = 0; c < n; ++c) {
    events.push_back({d.crossings[c].over_edge, d.crossings[c].over_param, c, false});
    events.push_back({d.crossings[c].under_edge, d.crossings[c].under_param, c, true});
  }
  std::sort(events.begin(), events.end(), [](const Event& x, const Event& y) {
    return x.edge != y.edge ? x.edge < y.edge : x.param < y.param;
  });
  // Arc k starts after the k-th undercrossing along the curve; the stretch before the first
  // one belongs to the last arc (the curve is closed).
  std::vector<int> over(n), in(n), out(n);
  int arc = 0;
  for (const Event& e : events) {
    if (e.under) {
      in[e.crossing] = arc;
      arc = arc + 1;
      out[e.crossing] = arc % n;
    } else {
      over[e.crossing] = arc;
    }
  }
  // Stretch before the first undercrossing is arc n, which is arc 0 closed up.
  for (int c = 0; c < n; ++c) {
    over[c] %= n;
    in[c] %= n;
  }
  std::vector<std::vector<Linear>> m(n, std::vector<Linear>(n));
  for (int c = 0; c < n; ++c) {
    const int sign = d.crossings[c].sign;
    m[c][over[c]].a += 1;
    m[c][over[c]].b -= 1;
    // Positive: x_out = x_over x_in x_over^-1 -> t on in, -1 on out (Fox calculus).
    if (sign > 0) {
      m[c][in[c]].b += 1;
      m[c][out[c]].a -= 1;
    } else {
      m[c][in[c]].a -= 1;
      m[c][out[c]].b += 1;
    }
  }
  m.pop_back();
  for (auto& row : m) row.pop_back();
  return m;
}

std::uint64_t MulMod(std::uint64_t a, std::uint64_t b, std::uint64_t p) {
  return static_cast<std::uint64_t>(static_cast<UInt>(a) * b % p);
}

std::uint64_t PowMod(std::uint64_t a, std::uint64_t e, std::uint64_t p) {
  std::uint64_t r = 1;
  for (; e; e >>= 1, a = MulMod(a, a, p))
    if (e & 1) r = MulMod(r, a, p);
  return r;
}

// det(m at t) mod p by Gaussian elimination (p prime).
std::uint64_t DetMod(const std::vector<std::vector<Linear>>& m, std::int64_t t,
                     std::uint64_t p) {
  const int n = static_cast<int>(m.size());
  std::vector<std::vector<std::uint64_t>> a(n, std::vector<std::uint64_t>(n));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const std::int64_t v = m[i][j].a + m[i][j].b * t;
      const std::int64_t r = v % static_cast<std::int64_t>(p);
      a[i][j] = static_cast<std::uint64_t>(r < 0 ? r + static_cast<std::int64_t>(p) : r);
    }
  std::uint64_t det = 1;
  for (int k = 0; k < n; ++k) {
    int piv = k;
    while (piv < n && a[piv][k] == 0) ++piv;
    if (piv == n) return 0;
    if (piv != k) {
      std::swap(a[piv], a[k]);
      det = (p - det) % p;
    }
    det = MulMod(det, a[k][k], p);
    const std::uint64_t inv = PowMod(a[k][k], p - 2, p);
    for (int i = k + 1; i < n; ++i) {
      if (a[i][k] == 0) continue;
      const std::uint64_t f = MulMod(a[i][k], inv, p);
      for (int j = k; j < n; ++j) a[i][j] = (a[i][j] + p - MulMod(f, a[k][j], p)) % p;
    }
  }
  return det;
}

// Symmetric residue in (-p/2, p/2].
std::int64_t Symmetric(std::uint64_t r, std::uint64_t p) {
  return r > p / 2 ? -static_cast<std::int64_t>(p - r) : static_cast<std::int64_t>(r);
}

void Trim(Poly& p) {
  while (!p.empty() && p.back() == 0) p.pop_back();
}

std::optional<Int> Mul(Int a, Int b) {
  Int r;
  if (__builtin_mul_overflow(a, b, &r)) return std::nullopt;
  return r;
}

// a*b - c*e, or nothing on overflow.
std::optional<Poly> MulSub(const Poly& a, const Poly& b, const Poly& c, const Poly& e) {
  const std::size_t len = std::max(a.empty() || b.empty() ? 0 : a.size() + b.size() - 1,
                                   c.empty() || e.empty() ? 0 : c.size() + e.size() - 1);
  Poly r(len, 0);
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = 0; j < b.size(); ++j) {
      auto v = Mul(a[i], b[j]);
      if (!v || __builtin_add_overflow(r[i + j], *v, &r[i + j])) return std::nullopt;
    }
  for (std::size_t i = 0; i < c.size(); ++i)
    for (std::size_t j = 0; j < e.size(); ++j) {
      auto v = Mul(c[i], e[j]);
      if (!v || __builtin_sub_overflow(r[i + j], *v, &r[i + j])) return std::nullopt;
    }
  Trim(r);
  return r;
}

// Exact division num / den in Z[t] (Bareiss guarantees it); nothing if it is not exact.
std::optional<Poly> DivExact(Poly num, const Poly& den) {
  if (num.empty()) return Poly{};
  if (den.empty() || num.size() < den.size()) return std::nullopt;
  Poly q(num.size() - den.size() + 1, 0);
  for (std::size_t k = q.size(); k-- > 0;) {
    const Int top = num[k + den.size() - 1];
    if (top % den.back() != 0) return std::nullopt;
    q[k] = top / den.back();
    for (std::size_t j = 0; j < den.size(); ++j) {
      auto v = Mul(q[k], den[j]);
      if (!v || __builtin_sub_overflow(num[k + j], *v, &num[k + j])) return std::nullopt;
    }
  }
  for (const Int& x : num)
    if (x != 0) return std::nullopt;
  Trim(q);
  return q;
}

// det over Z[t], up to sign, by Bareiss elimination; nothing on overflow.
std::optional<Poly> DetPoly(const std::vector<std::vector<Linear>>& m) {
  const int n = static_cast<int>(m.size());
  if (n == 0) return Poly{1};
  std::vector<std::vector<Poly>> a(n, std::vector<Poly>(n));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      a[i][j] = {m[i][j].a, m[i][j].b};
      Trim(a[i][j]);
    }
  Poly prev{1};
  for (int k = 0; k < n; ++k) {
    int piv = -1;
    for (int i = k; i < n; ++i)
      if (!a[i][k].empty() && (piv < 0 || a[i][k].size() < a[piv][k].size())) piv = i;
    if (piv < 0) return Poly{};
    std::swap(a[piv], a[k]);
    for (int i = k + 1; i < n; ++i) {
      for (int j = k + 1; j < n; ++j) {
        auto v = MulSub(a[k][k], a[i][j], a[i][k], a[k][j]);
        if (!v) return std::nullopt;
        auto q = DivExact(std::move(*v), prev);
        if (!q) return std::nullopt;
        a[i][j] = std::move(*q);
      }
      a[i][k].clear();
    }
    prev = a[k][k];
  }
  return a[n - 1][n - 1];
}

}  // namespace

AlexanderResult ComputeAlexander(const Diagram& diagram) {
  AlexanderResult res;
  const int n = static_cast<int>(diagram.crossings.size());
  if (n == 0) {
    res.ok = true;
    res.determinant = 1;
    res.polynomial = {1};
    return res;
  }
  const auto m = AlexanderMatrix(diagram);
  // Δ(1) = ±1 for every knot diagram: a cheap check that the arcs were read right.
  constexpr std::array<std::uint64_t, 2> kPrimes = {2305843009213693951ULL,   // 2^61 - 1
                                                    2305843009213693921ULL};  // prime
  const std::int64_t at_one = Symmetric(DetMod(m, 1, kPrimes[0]), kPrimes[0]);
  if (std::abs(at_one) != 1) return res;
  const std::int64_t d0 = Symmetric(DetMod(m, -1, kPrimes[0]), kPrimes[0]);
  const std::int64_t d1 = Symmetric(DetMod(m, -1, kPrimes[1]), kPrimes[1]);
  res.ok = true;
  res.determinant = (d0 == d1 && std::abs(d0) < (std::int64_t{1} << 60)) ? std::abs(d0) : -1;
  if (n > kMaxPolynomialCrossings) return res;
  auto poly = DetPoly(m);
  if (!poly || poly->empty()) return res;
  // Strip the factor t^k, then the sign: Δ(1) = +1.
  std::size_t low = 0;
  while ((*poly)[low] == 0) ++low;
  Int sum = 0;
  for (std::size_t i = low; i < poly->size(); ++i) sum += (*poly)[i];
  if (sum != 1 && sum != -1) return res;
  for (std::size_t i = low; i < poly->size(); ++i) {
    const Int c = sum * (*poly)[i];
    if (c > INT64_MAX || c < INT64_MIN) {
      res.polynomial.clear();
      return res;
    }
    res.polynomial.push_back(static_cast<std::int64_t>(c));
  }
  return res;
}

}  // namespace snapthread::topology

