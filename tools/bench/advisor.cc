// Advisor: the smallest n and the cheapest method / cutoff / budget meeting a scene's targets.
#include "bench_support.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "models/models.h"

namespace snapthread {

namespace fs = std::filesystem;

// ---------------------------------------------------------------- advisor

bool IsChain(const Scene& s) { return IsChain(s.params); }

Scene ResizeChain(const Scene& scene, int n) {
  if (!IsChain(scene)) return scene;
  Scene s = scene;
  // EI = beta l and EA ~ 2 gamma l are the continuum constants: keep beta l, gamma l.
  s.params = ResizeChain(scene.params, n);
  return s;
}

std::vector<Vec> HandSpeedPath(const Scene& scene) {
  constexpr double kStep = 0.002;                          // model units per update
  constexpr double kTurn = 0.5 * std::numbers::pi / 180;   // grip turn per update, rad
  const int pos = scene.grasp_layout.spatial_dimension;
  int steps = 1;
  for (size_t k = 1; k < scene.path.size(); ++k) {
    const Vec& a = scene.path[k - 1];
    const Vec& b = scene.path[k];
    double need = (b.head(pos) - a.head(pos)).norm() / kStep;
    if (scene.grasp_layout.grip_direction) {
      const double c = std::clamp(a.tail(3).normalized().dot(b.tail(3).normalized()), -1.0, 1.0);
      need = std::max(need, std::acos(c) / kTurn);
    }
    steps = std::max(steps, static_cast<int>(std::ceil(need - 1e-2)));
  }
  return PathControls(scene, steps);
}

std::vector<SweepRow> TightTrace(const Scene& scene, const std::vector<Vec>& controls, int substeps,
                                 int max_iterations) {
  return ReferenceTrace(scene, controls, substeps, max_iterations);
}

int SelectCheapest(const std::vector<AdviceCandidate>& c, double te, double tr) {
  double fastest = -1.0;
  for (const auto& x : c)
    if (x.Acceptable(te, tr)) fastest = std::max(fastest, x.rate_hz);
  if (fastest < 0) return -1;
  // Rates within kRateTieFraction of the fastest are within the measurement noise of a
  // shared machine: among those the more accurate configuration wins.
  int best = -1;
  for (size_t i = 0; i < c.size(); ++i) {
    if (!c[i].Acceptable(te, tr) || c[i].rate_hz < (1.0 - kRateTieFraction) * fastest) continue;
    if (best < 0 || c[i].force_error < c[best].force_error ||
        (c[i].force_error == c[best].force_error && c[i].rate_hz > c[best].rate_hz))
      best = static_cast<int>(i);
  }
  return best;
}

namespace {

// Every configuration (method x cutoff x budget) timed on the scene sc (model size n,
// 0 for a scene that is not a chain), with its force error against the reference trace.
std::vector<AdviceCandidate> TimeCandidates(const Scene& sc, int n, const std::vector<Vec>& path,
                                            const AdvisorOptions& o, const std::vector<SweepRow>& ref,
                                            double scale) {
  std::vector<AdviceCandidate> here;
  for (const std::string& m : o.methods)
    for (double cutoff : o.cutoffs)
      for (int budget : o.budgets) {
        const TimedSweep t = TimeSweep(WithSolver(sc, m, cutoff, budget), path, o.repetitions, o.min_time_s);
        AdviceCandidate cand;
        cand.n = n;
        cand.method = m;
        cand.cutoff = cutoff;
        cand.budget = budget;
        cand.rate_hz = t.rate_hz.median;
        cand.force_error = RelativeRmsForceError(t.rows, ref, scale);
        cand.spurious_reversals = Compare(t.rows, ref).spurious_reversals;
        here.push_back(cand);
      }
  return here;
}

// Why no configuration was chosen after the whole ladder.
std::string NoChoiceMessage(const Advice& a, bool chain, const std::vector<int>& ladder) {
  std::ostringstream msg;
  msg << "no configuration meets both targets: ";
  if (chain) {
    const ModelErrorRow* best = nullptr;
    for (const auto& m : a.model_errors)
      if (!best || m.force_error < best->force_error) best = &m;
    msg << "along the ladder (up to n = " << ladder.back() << ") the smallest model error is "
        << Sci(best ? best->force_error : 0.0) << " (n = " << (best ? best->n : 0) << ")";
    if (!a.candidates.empty()) msg << "; where the model was fine enough, no fast configuration was accurate enough";
    msg << ", target " << Sci(a.target_force_error);
  } else {
    msg << "no fast enough configuration reaches a force error of " << Sci(a.target_force_error);
  }
  return msg.str();
}

}  // namespace

Advice Advise(const Scene& scene, const AdvisorOptions& o, std::ostream* progress) {
  Advice a;
  a.target_force_error = o.target_force_error > 0 ? o.target_force_error : scene.target_force_error;
  a.target_rate_hz = o.target_rate_hz > 0 ? o.target_rate_hz : scene.target_rate_hz;
  if (!(a.target_force_error > 0) || !(a.target_rate_hz > 0))
    throw std::invalid_argument("advise: " + scene.file +
                                " states no targets: add targets: {force_error: <relative to the force scale>, "
                                "rate_hz: <updates per second>} or pass both targets on the command line");
  const std::vector<Vec> path = o.path.empty() ? HandSpeedPath(scene) : o.path;
  const bool chain = IsChain(scene);
  std::vector<int> ladder = o.n_ladder;
  std::sort(ladder.begin(), ladder.end());
  ladder.erase(std::unique(ladder.begin(), ladder.end()), ladder.end());
  if (!chain || ladder.empty()) ladder = {chain ? ChainSegments(scene.params) : 0};

  Scene ref_scene = scene;
  if (chain) {
    a.reference_n = o.reference_n > 0 ? o.reference_n : 2 * std::max(ChainSegments(scene.params), ladder.back());
    ref_scene = ResizeChain(scene, a.reference_n);
    // A rung as fine as the reference would compare the reference with itself.
    std::erase_if(ladder, [&](int n) { return n >= a.reference_n; });
    if (ladder.empty()) throw std::invalid_argument("advise: every n of the ladder is >= the reference n");
  }
  const double scale = ForceScaleOf(ref_scene);
  const auto t_ref = Clock::now();
  const auto ref = TightTrace(ref_scene, path, std::max(1, o.substeps), o.tight_max_iterations);
  if (progress)
    *progress << "advise: " << scene.name << ": " << path.size() << " updates along grasp.path; reference"
              << (chain ? " n=" + std::to_string(a.reference_n) : std::string()) << " in " << std::fixed
              << std::setprecision(1) << Seconds(t_ref, Clock::now()) << " s\n"
              << std::defaultfloat << std::flush;

  for (int n : ladder) {
    const Scene sc = chain ? ResizeChain(scene, n) : scene;
    if (chain) {
      // The model's own error: the n-segment chain solved tightly, against the fine one.
      const double e = RelativeRmsForceError(TightTrace(sc, path, 1, o.tight_max_iterations), ref, scale);
      a.model_errors.push_back({n, e});
      if (progress) *progress << "advise: n=" << n << ": model error " << Sci(e) << '\n' << std::flush;
      if (e > a.target_force_error) continue;
    }
    const std::vector<AdviceCandidate> here = TimeCandidates(sc, chain ? n : 0, path, o, ref, scale);
    a.candidates.insert(a.candidates.end(), here.begin(), here.end());
    const int best = SelectCheapest(here, a.target_force_error, a.target_rate_hz);
    if (progress)
      *progress << "advise: " << (chain ? "n=" + std::to_string(n) + ": " : std::string()) << here.size()
                << " configurations timed, " << (best >= 0 ? "one meets both targets" : "none meets both targets")
                << '\n'
                << std::flush;
    if (best >= 0) {
      a.found = true;
      a.choice = here[best];
      std::ostringstream msg;
      msg << "smallest model meeting the force target: "
          << (chain ? "n = " + std::to_string(n) : std::string("the scene's model")) << "; fastest configuration "
          << "meeting both targets: " << a.choice.method << ", cutoff " << Sci(a.choice.cutoff, 0)
          << ", budget " << BudgetText(a.choice.budget) << " (" << Sci(a.choice.rate_hz) << " updates/s, force error "
          << Sci(a.choice.force_error) << ")";
      a.message = msg.str();
      return a;
    }
    double fastest = 0.0;
    for (const auto& c : here) fastest = std::max(fastest, c.rate_hz);
    if (fastest < a.target_rate_hz) {
      std::ostringstream msg;
      msg << "no configuration meets both targets: the fastest at "
          << (chain ? "n = " + std::to_string(n) : std::string("the scene's model")) << " gives " << Sci(fastest)
          << " updates/s < " << Sci(a.target_rate_hz) << (chain ? " and larger n are only slower" : "");
      a.message = msg.str();
      return a;
    }
    // Fast enough but every fast configuration is too inaccurate: a finer model may help.
  }
  a.message = NoChoiceMessage(a, chain, ladder);
  return a;
}

void PrintAdvice(const Advice& a, std::ostream& out) {
  char buf[256];
  out << "targets: force error (rms |F - F_ref| / ForceScale) <= " << Sci(a.target_force_error)
      << ", rate >= " << Sci(a.target_rate_hz) << " updates/s\n";
  if (!a.model_errors.empty()) {
    out << "model error of each n (tight solve against the n=" << a.reference_n << " reference):\n";
    for (const auto& m : a.model_errors) {
      std::snprintf(buf, sizeof buf, "  n=%-5d %10.3e %s\n", m.n, m.force_error,
                    m.force_error <= a.target_force_error ? "meets" : "too coarse");
      out << buf;
    }
  }
  out << "configurations timed:\n";
  std::snprintf(buf, sizeof buf, "  %5s %-12s %7s %6s %11s %10s %8s  %s\n", "n", "method", "cutoff", "budget",
                "rate(1/s)", "|dF|/Fs", "chatter", "meets");
  out << buf;
  for (const auto& c : a.candidates) {
    const bool e = c.MeetsError(a.target_force_error) && c.spurious_reversals == 0,
               r = c.MeetsRate(a.target_rate_hz);
    const bool chosen = a.found && c.n == a.choice.n && c.method == a.choice.method && c.cutoff == a.choice.cutoff &&
                        c.budget == a.choice.budget;
    std::snprintf(buf, sizeof buf, "  %5d %-12s %7.0e %6s %11.3e %10.3e %8d  %s%s\n", c.n, c.method.c_str(),
                  c.cutoff, BudgetText(c.budget).c_str(), c.rate_hz, c.force_error, c.spurious_reversals,
                  e && r ? "both" : (e ? "error only" : (r ? "rate only" : "neither")), chosen ? "   <== choice" : "");
    out << buf;
  }
  out << (a.found ? "advice: " : "advice: none: ") << a.message << '\n';
}


}  // namespace snapthread
