// Flood chart of snapthread-bench: a genuine session (snapthread-server and
// snapthread-device over udpm loopback, one session key) measured without and with a
// keyless flood of forged messages on every session channel (flood_forger.h). Per run:
// the device's servo tick rate and the age of the model it renders (p50 / p99), both from
// its per-tick --trace after the start-up and before the exit fade; the server's update
// rate; the refusals both count. Runs alternate without / with the flood, so slow phases
// of a shared machine hit both. The targets it reports against: the device keeps
// >= 990 Hz with models <= 5 ms old, and the server's update rate stays within 10 % of
// its rate without the flood.
#pragma once

#include <ostream>
#include <string>
#include <vector>

namespace snapthread {

struct FloodBenchOptions {
  std::string bin_dir;     // holds snapthread-server and snapthread-device
  std::string scenes_dir;
  std::string scene = "curve2d_snap";
  double duration_s = 10.0;            // device run per measurement
  double skip_s = 1.0;                 // trace rows before this (start-up) are not counted
  int repetitions = 3;                 // pairs of runs (without, with the flood)
  double rate_per_channel_hz = 10000.0;
  // Loopback only (ttl=0) and a group and port of the bench's own: the flood must not
  // reach a session on the default group of this host or the LAN.
  std::string lcm_url = "udpm://239.255.76.95:7695?ttl=0";
  std::string work_dir;                // keys, logs, summaries, traces
  // The device's servo thread with SCHED_FIFO + mlockall (as in the lab) instead of
  // --no-rt (the service chart's default); needs the privilege, else the device says so.
  bool realtime = false;
};

struct FloodRun {
  int repetition = 0;
  bool flood = false;
  bool ok = false;
  std::string error;
  double flood_rate_per_channel_hz = 0.0;  // achieved by the forger
  double window_tick_rate_hz = 0.0;        // servo ticks / s over the trace window
  double tick_rate_hz = 0.0;               // device summary: whole run, start and exit included
  double model_age_ms_p50 = 0.0, model_age_ms_p99 = 0.0, model_age_ms_max = 0.0;
  double fading_fraction = 0.0;            // traced ticks that faded (stale model)
  double server_update_rate_hz = 0.0;      // server summary: first to last update
  double server_updates = 0.0;
  double models_received = 0.0, models_rejected = 0.0;  // device
  double server_rejected = 0.0;                         // server rejected_messages
  double max_force_n = 0.0, max_abs_fz_n = 0.0;         // rendered
  bool realtime = false;                                // the device's summary says SCHED_FIFO was active
};

// One session (never throws); `flood` starts the forger before the device and stops it
// after the device has exited.
FloodRun RunFloodOnce(const FloodBenchOptions& options, bool flood, int repetition);
std::vector<FloodRun> RunFloodBench(const FloodBenchOptions& options, std::ostream* progress);
void WriteFloodCsv(const std::vector<FloodRun>& runs, std::ostream& out);
// Medians per condition, the flooded / quiet ratios and the targets, met or not.
void PrintFloodSummary(const std::vector<FloodRun>& runs, std::ostream& out);

}  // namespace snapthread
