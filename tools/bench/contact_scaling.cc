// The contact line of the scaling chart ("contact cost linear in n"):
// self-contact's energy, gradient and Hessian (contact/self_contact.h: broad phase, then
// the narrow phase on its candidate pairs) on a close helix of n segments, where every
// segment lies within the barrier's reach of the turns above and below it, so the active
// pairs grow like n. The positions alternate between two jittered copies of the helix so
// that no evaluation reuses the last one's pair list (SelfContact caches it per state).
#include <algorithm>
#include <cmath>
#include <random>

#include "bench_support.h"
#include "contact/self_contact.h"

namespace snapthread {

std::vector<ContactScalingRow> RunContactScaling(const std::vector<int>& ns, int repetitions, double min_sample_s) {
  // Segments of 0.1 on a helix of radius 0.2 (0.5 rad each), turns 0.05 apart: capsules
  // of radius 0.02 leave a gap of 0.01 between turns, inside d-hat = 0.02.
  const contact::ContactParams params{.enabled = true, .radius = 0.02, .dhat = 0.02, .stiffness = 1.0};
  std::vector<ContactScalingRow> rows;
  std::mt19937 rng(15);
  std::uniform_real_distribution<double> jitter(-1e-4, 1e-4);
  for (const int n : ns) {
    const contact::SelfContact sc(params, n, 0.1);
    Eigen::Matrix3Xd nodes[2] = {Eigen::Matrix3Xd(3, n + 1), Eigen::Matrix3Xd(3, n + 1)};
    for (int c = 0; c < 2; ++c) {
      for (int k = 0; k <= n; ++k) {
        const double a = 0.5 * k;
        nodes[c].col(k) = Eigen::Vector3d(0.2 * std::cos(a) + jitter(rng), 0.2 * std::sin(a) + jitter(rng),
                                          0.05 * a / (2.0 * M_PI) + jitter(rng));
      }
    }
    ContactScalingRow row;
    row.n = n;
    double sink = 0.0;
    auto evaluate = [&](const Eigen::Matrix3Xd& x) {
      sink += sc.Energy(x);
      int active = 0;
      sc.ForEachActive(x, true, [&](int, int, const contact::Vec12& g, const contact::Mat12& h) {
        sink += g[0] + h(0, 0);
        ++active;
      });
      row.active_pairs = active;
      row.candidate_pairs = sc.CandidatePairs();
    };
    evaluate(nodes[0]);  // warm: scratch sized
    std::vector<double> rates;
    for (int rep = 0; rep < repetitions; ++rep) {
      long count = 0;
      const Clock::time_point start = Clock::now();
      double elapsed = 0.0;
      while (elapsed < min_sample_s || count < 20) {
        evaluate(nodes[count % 2]);
        ++count;
        elapsed = Seconds(start, Clock::now());
      }
      rates.push_back(count / elapsed);
    }
    if (!std::isfinite(sink)) row.active_pairs = -1;  // keeps the work observable
    row.rate_hz = Summarize(rates);
    rows.push_back(row);
  }
  return rows;
}

void WriteContactScalingCsv(const std::vector<ContactScalingRow>& rows, std::ostream& out) {
  out << "n,rate_hz_median,rate_hz_min,rate_hz_max,active_pairs,candidate_pairs\n";
  for (const auto& r : rows) {
    out << r.n << ',' << r.rate_hz.median << ',' << r.rate_hz.min << ',' << r.rate_hz.max << ',' << r.active_pairs
        << ',' << r.candidate_pairs << '\n';
  }
}

PowerLawFit FitContactScaling(const std::vector<ContactScalingRow>& rows, int min_n) {
  std::vector<double> x, y;
  for (const auto& r : rows) {
    if (r.n < min_n) continue;
    x.push_back(r.n);
    y.push_back(r.rate_hz.median);
  }
  return FitPowerLaw(x, y);
}

}  // namespace snapthread
