// Flood chart: a genuine server + device session without and with a keyless flood.
#include "flood.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "bench_support.h"
#include "flood_forger.h"
#include "realtime/percentiles.h"

namespace snapthread {

namespace fs = std::filesystem;

namespace {

// The device's --trace (device_client.cc: t_s, seq = tick, x, y, z, fx, fy, fz,
// model_age_ms, model_status, clamped, fading, ...) over [skip_s, end - kTailSeconds]: the
// start-up (no model yet) and the fade-out at exit are not the steady state. Rendered
// force maxima over the whole trace.
constexpr double kTailSeconds = 0.25;  // > the device's 100 ms exit fade

bool ReadTrace(const std::string& path, double skip_s, FloodRun* run) {
  std::ifstream in(path);
  std::string line;
  if (!std::getline(in, line)) return false;  // header
  std::vector<std::array<double, 12>> rows;
  while (std::getline(in, line)) {
    std::array<double, 12> f{};
    std::stringstream ss(line);
    std::string cell;
    int k = 0;
    while (k < 12 && std::getline(ss, cell, ',')) f[k++] = std::strtod(cell.c_str(), nullptr);
    if (k < 12) continue;
    const double force = std::sqrt(f[5] * f[5] + f[6] * f[6] + f[7] * f[7]);
    run->max_force_n = std::max(run->max_force_n, force);
    run->max_abs_fz_n = std::max(run->max_abs_fz_n, std::fabs(f[7]));
    rows.push_back(f);
  }
  if (rows.empty()) return false;
  const double end_s = rows.back()[0] - kTailSeconds;
  std::vector<double> ages;
  long counted = 0, fading = 0;
  const std::array<double, 12>* first = nullptr;
  const std::array<double, 12>* last = nullptr;
  for (const auto& f : rows) {
    if (f[0] < skip_s || f[0] > end_s) continue;
    if (first == nullptr) first = &f;
    last = &f;
    ++counted;
    if (f[11] != 0.0) ++fading;
    if (f[8] >= 0.0) ages.push_back(f[8]);
  }
  if (counted < 2 || (*last)[0] <= (*first)[0]) return false;
  // Ticks (the trace's seq column) over time: the servo's steady rate in the window.
  run->window_tick_rate_hz = ((*last)[1] - (*first)[1]) / ((*last)[0] - (*first)[0]);
  // Nearest-rank percentiles, as the device's own lateness figures.
  realtime::SampleWindow window(std::max<size_t>(1, ages.size()));
  for (const double age : ages) window.Push(age);
  const realtime::PercentileSummary age = window.Compute();
  run->model_age_ms_p50 = age.p50;
  run->model_age_ms_p99 = age.p99;
  run->model_age_ms_max = age.max;
  // A tick without any model yet counts as fading: it renders nothing.
  run->fading_fraction = static_cast<double>(fading + (counted - static_cast<long>(ages.size()))) / counted;
  return true;
}

}  // namespace

FloodRun RunFloodOnce(const FloodBenchOptions& o, bool flood, int repetition) {
  FloodRun run;
  run.repetition = repetition;
  run.flood = flood;
  ServiceSession s;
  s.session = "FLOOD_" + std::to_string(getpid()) + "_" + std::to_string(repetition) + (flood ? "F" : "Q");
  s.lcm_url = o.lcm_url;
  s.duration_s = o.duration_s;
  if (!PrepareServiceSession(o.bin_dir, o.scenes_dir, o.scene, o.work_dir, &s, &run.error)) return run;
  s.key_path = s.base + ".key";
  if (!WriteSessionKey(s.key_path, &run.error)) return run;
  const pid_t server = StartServer(s, &run.error);
  if (server < 0) return run;
  flood::ForgerOptions forger_options;
  forger_options.lcm_url = o.lcm_url;
  forger_options.session = s.session;
  forger_options.rate_per_channel_hz = o.rate_per_channel_hz;
  flood::ForgedFlood forger(forger_options);
  std::string flood_error;
  if (flood && !forger.Start(&flood_error)) {
    kill(server, SIGTERM);
    WaitFor(server, 10);
    run.error = "flood: " + flood_error;
    return run;
  }
  std::vector<std::string> device_args = DeviceArgs(s);
  device_args.insert(device_args.end(), {"--trace", s.base + "_trace.csv"});
  if (!o.realtime) device_args.push_back("--no-rt");
  const pid_t device = Spawn(device_args, s.base + "_device.log");
  const int device_rc = device < 0 ? -1 : WaitFor(device, o.duration_s + 30.0);
  forger.Stop();
  run.flood_rate_per_channel_hz = forger.AchievedRatePerChannel();
  run.error = StopServer(server, device_rc, s);
  if (!run.error.empty()) return run;
  const std::string& base = s.base;
  const std::string dev = ReadFile(base + "_device.json");
  const std::string srv = ReadFile(base + "_server.json");
  const bool ok = JsonNumber(dev, "tick_rate_hz", &run.tick_rate_hz) &&
                  JsonNumber(dev, "models_received", &run.models_received) &&
                  JsonNumber(dev, "models_rejected", &run.models_rejected) &&
                  JsonNumber(srv, "update_rate_hz", &run.server_update_rate_hz) &&
                  JsonNumber(srv, "updates", &run.server_updates) &&
                  JsonNumber(srv, "rejected_messages", &run.server_rejected);
  run.realtime = dev.find("\"realtime\": true") != std::string::npos;
  if (!ok) {
    run.error = "a summary lacks a figure (" + base + "_device.json, _server.json)";
    return run;
  }
  if (!ReadTrace(base + "_trace.csv", o.skip_s, &run)) {
    run.error = "no trace rows after " + std::to_string(o.skip_s) + " s (" + base + "_trace.csv)";
    return run;
  }
  // The traces are large (1 kHz rows); the summaries and logs stay.
  std::error_code ec;
  fs::remove(base + "_trace.csv", ec);
  run.ok = true;
  return run;
}

std::vector<FloodRun> RunFloodBench(const FloodBenchOptions& o, std::ostream* progress) {
  std::vector<FloodRun> runs;
  for (int rep = 0; rep < std::max(1, o.repetitions); ++rep)
    for (const bool flood : {false, true}) {
      if (progress)
        *progress << "bench flood: " << o.scene << " run " << rep + 1 << "/" << o.repetitions
                  << (flood ? " with the flood (" : " without flood (") << o.duration_s << " s)\n"
                  << std::flush;
      runs.push_back(RunFloodOnce(o, flood, rep));
      if (progress && !runs.back().ok) *progress << "bench flood: failed: " << runs.back().error << '\n';
    }
  return runs;
}

void WriteFloodCsv(const std::vector<FloodRun>& runs, std::ostream& out) {
  out << "repetition,flood,ok,flood_rate_per_channel_hz,window_tick_rate_hz,tick_rate_hz,model_age_ms_p50,"
         "model_age_ms_p99,"
         "model_age_ms_max,fading_fraction,server_update_rate_hz,server_updates,models_received,models_rejected,"
         "server_rejected,max_force_n,max_abs_fz_n,realtime,error\n";
  for (const auto& r : runs)
    out << r.repetition << ',' << (r.flood ? 1 : 0) << ',' << (r.ok ? 1 : 0) << ',' << r.flood_rate_per_channel_hz
        << ',' << r.window_tick_rate_hz << ',' << r.tick_rate_hz << ',' << r.model_age_ms_p50 << ','
        << r.model_age_ms_p99 << ','
        << r.model_age_ms_max << ',' << r.fading_fraction << ',' << r.server_update_rate_hz << ','
        << r.server_updates << ',' << r.models_received << ',' << r.models_rejected << ',' << r.server_rejected
        << ',' << r.max_force_n << ',' << r.max_abs_fz_n << ',' << (r.realtime ? 1 : 0) << ",\"" << r.error
        << "\"\n";
}

void PrintFloodSummary(const std::vector<FloodRun>& runs, std::ostream& out) {
  struct Medians {
    Spread tick, age50, age99, server, flood_rate, rejected, server_rejected, fading, fz;
    int ok = 0, total = 0;
  };
  auto medians = [&](bool flood) {
    Medians m;
    std::vector<double> t, a, b, s, f, r, sr, fa, fz;
    for (const auto& run : runs) {
      if (run.flood != flood) continue;
      ++m.total;
      if (!run.ok) continue;
      ++m.ok;
      t.push_back(run.window_tick_rate_hz);
      a.push_back(run.model_age_ms_p50);
      b.push_back(run.model_age_ms_p99);
      s.push_back(run.server_update_rate_hz);
      f.push_back(run.flood_rate_per_channel_hz);
      r.push_back(run.models_rejected);
      sr.push_back(run.server_rejected);
      fa.push_back(run.fading_fraction);
      fz.push_back(run.max_abs_fz_n);
    }
    m.tick = Summarize(t);
    m.age50 = Summarize(a);
    m.age99 = Summarize(b);
    m.server = Summarize(s);
    m.flood_rate = Summarize(f);
    m.rejected = Summarize(r);
    m.server_rejected = Summarize(sr);
    m.fading = Summarize(fa);
    m.fz = Summarize(fz);
    return m;
  };
  const Medians quiet = medians(false), flooded = medians(true);
  // Paired ratios: each flooded run against the quiet run of its repetition.
  std::vector<double> paired;
  for (const auto& f : runs) {
    if (!f.flood || !f.ok) continue;
    for (const auto& q : runs)
      if (!q.flood && q.ok && q.repetition == f.repetition && q.server_update_rate_hz > 0)
        paired.push_back(f.server_update_rate_hz / q.server_update_rate_hz);
  }
  const Spread ratio = Summarize(paired);
  char buf[512];
  auto row = [&](const char* name, const Medians& m) {
    std::snprintf(buf, sizeof buf,
                  "%-14s %2d/%-2d %8.0f %12.1f [%.1f..%.1f] %8.2f %8.2f [%.2f..%.2f] "
                  "%10.0f [%.0f..%.0f] %10.0f %10.0f %9.4f %8.3f\n",
                  name, m.ok, m.total, m.flood_rate.median, m.tick.median, m.tick.min, m.tick.max, m.age50.median,
                  m.age99.median, m.age99.min, m.age99.max, m.server.median, m.server.min, m.server.max,
                  m.rejected.median, m.server_rejected.median, m.fading.median, m.fz.median);
    out << buf;
  };
  out << "flood: median [min..max] over the runs; forged msgs/s per channel on 6 channels\n";
  std::snprintf(buf, sizeof buf, "%-14s %5s %8s %24s %8s %22s %28s %10s %10s %9s %8s\n", "condition", "runs",
                "forged/s", "device tick Hz", "age p50", "age p99 ms", "server updates/s", "dev rej", "srv rej",
                "fading", "|fz| N");
  out << buf;
  row("quiet", quiet);
  row("flooded", flooded);
  std::snprintf(buf, sizeof buf,
                "server update rate flooded / quiet: %.3f median of %d paired runs [%.3f..%.3f]; of medians %.3f\n",
                ratio.median, ratio.count, ratio.min, ratio.max,
                quiet.server.median > 0 ? flooded.server.median / quiet.server.median : 0.0);
  out << buf;
  auto met = [](bool b) { return b ? "met" : "NOT met"; };
  std::snprintf(buf, sizeof buf,
                "targets under the flood: device >= 990 Hz: %s (%.1f); model age p99 <= 5 ms: %s (%.2f ms); "
                "server rate within 10 %%: %s (%.3f)\n",
                met(flooded.tick.median >= 990.0), flooded.tick.median, met(flooded.age99.median <= 5.0),
                flooded.age99.median, met(ratio.count > 0 && std::fabs(ratio.median - 1.0) <= 0.10), ratio.median);
  out << buf;
}

}  // namespace snapthread
