// Analysis of one session's messages in an LCM log: counts and sequence gaps per channel,
// force against time with snaps, solver statistics, device timing. Fed event by event
// (ReadLog), then written out as CSV files and a summary.txt.
#pragma once

#include <cstdint>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "log_reader.h"
#include "sequence_tracker.h"

namespace snapthread::report {

struct ChannelStats {
  std::string type;            // message type by channel suffix, "" for foreign channels
  int64_t messages = 0;
  int64_t bytes = 0;
  int64_t rejected = 0;        // failed decode or validation (reason of the first in note)
  std::string first_rejection;
  bool has_seq = false;
  SequenceTracker seq;
  double first_s = 0.0, last_s = 0.0;  // log time of first / last message
};

// error_n: the model's certified force error (force_model_t.force_error_n, N; < 0: none);
// grasp: the index of its grasp name in SessionReview::grasps().
struct ForceRow { double t_s; double f[3]; double norm_n; int status; int64_t seq; double error_n; int grasp; };
struct SolveRow { double t_s; int iterations; double residual; int solve_us; int status; };
struct StatusRow {
  double t_s; std::string method; int iterations; double residual; double lambda_min;
  int negative_pivots; double update_rate_hz; double solve_us_p50; double solve_us_p99;
  int64_t dropped_poses;
};
struct DeviceRow {
  double t_s; double tick_rate_hz; double lateness_p50_us; double lateness_p99_us;
  double lateness_max_us; double model_age_ms; double rt_p50_us; double rt_p99_us;
  double force_norm_n; int64_t force_clamps; int64_t stiffness_clamps; int64_t slew_limits;
  int64_t fades; int64_t snaps_felt;
};
// solver_status_t's knot type and active contacts.
struct KnotRow { double t_s; std::string knot; int determinant; int contacts; };
struct RoundTripRow { double t_s; double loop_us; double server_us; };

// Picks the session with the most messages among channels named <SESSION>_<KNOWN SUFFIX>
// whose <SESSION> is a valid session name (messages::IsValidSessionName); "" when there is
// none. A hostile channel name is never chosen, however busy.
std::string InferSession(const std::map<std::string, int64_t>& channel_counts);

class SessionReview {
 public:
  // Channels listed one by one; messages on further channels are only counted.
  static constexpr size_t kMaxListedChannels = 1000;
  // Grasp names told apart in the force rows; further names share the last index.
  static constexpr size_t kMaxGrasps = 16;

  explicit SessionReview(std::string session);
  void Add(const lcm::LogEvent& event);

  // Writes the CSV files into `dir` (which must exist); returns the file names written.
  std::vector<std::string> WriteCsv(const std::string& dir) const;
  // summary.txt text; `plots` lists PNGs written and `notes` anything worth saying.
  std::string Summary(const std::string& log_path, const LogReadStats& read,
                      const std::vector<std::string>& plots,
                      const std::vector<std::string>& notes) const;

  const std::map<std::string, ChannelStats>& channels() const { return channels_; }
  bool HasForce() const { return !force_.empty(); }
  // Some force model carried a certified force error (force_error_n >= 0).
  bool HasForceError() const;
  // The grasp names of the force models in the order first seen (raw; shown escaped).
  const std::vector<std::string>& grasps() const { return grasps_; }
  bool HasSolverStatus() const { return !status_.empty(); }
  bool HasDevice() const { return !device_.empty(); }
  bool HasRoundTrip() const { return !round_trip_.empty(); }
  bool HasSolve() const { return !solve_.empty(); }
  // Some status carried a knot type or a contact (older servers send neither).
  bool HasKnot() const;
  const std::string& session() const { return session_; }

 private:
  // Summary()'s sections, in its order: channels and sequence gaps; force, snaps and
  // latest-wins; solver; knot; device and round trip.
  void SummaryChannels(std::ostream& s) const;
  void SummaryForce(std::ostream& s) const;
  void SummaryForceError(std::ostream& s) const;
  int GraspIndex(const std::string& grasp);
  void SummarySolver(std::ostream& s) const;
  void SummaryKnot(std::ostream& s) const;
  void SummaryDevice(std::ostream& s) const;

  double TimeS(int64_t utime) const { return (utime - t0_us_) * 1e-6; }

  std::string session_;
  int64_t t0_us_ = -1;
  double last_s_ = 0.0;
  std::map<std::string, ChannelStats> channels_;  // by the raw name; shown escaped
  int64_t unlisted_messages_ = 0, unlisted_bytes_ = 0;  // beyond kMaxListedChannels
  std::vector<ForceRow> force_;
  std::vector<std::string> grasps_;
  std::vector<double> snap_times_s_;
  std::vector<SolveRow> solve_;
  std::vector<StatusRow> status_;
  std::vector<DeviceRow> device_;
  std::vector<KnotRow> knot_;
  std::vector<RoundTripRow> round_trip_;
  std::map<int64_t, int64_t> pose_log_time_us_;  // device seq -> log time (recent poses)
  int64_t shape_snaps_first_ = -1, shape_snaps_last_ = -1;
  // Latest wins (DESIGN.md): the server answers the newest pose and skips older queued
  // ones, so force_model_t.device_seq may jump but must never go back.
  int64_t first_answered_pose_ = -1;
  int64_t last_answered_pose_ = -1;
  int64_t answered_poses_ = 0;        // force models answering a newer pose than the last
  int64_t device_seq_regressions_ = 0;  // a model answering an older pose than a previous one
};

}  // namespace snapthread::report
