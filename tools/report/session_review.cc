#include "session_review.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include "auth/sealed_message.h"
#include "messages/channels.h"
#include "messages/validate.h"

namespace snapthread::report {
namespace {

constexpr const char* kSuffixes[] = {"_DEVICE_STATE", "_FORCE_MODEL",   "_SHAPE",
                                     "_SOLVER_STATUS", "_DEVICE_STATUS", "_COMMAND",
                                     "_COMMAND_REPLY"};
constexpr size_t kMaxRememberedPoses = 20000;

// Text from the log (channel names, method and knot strings) as it may appear in the
// summary and in CSV cells: escaped (no comma, quote, newline or control byte survives).
std::string Shown(const std::string& text) { return messages::EscapeForDisplay(text); }

std::string TypeOf(const std::string& channel, const std::string& session) {
  if (channel.rfind(session + "_", 0) != 0) return "";
  const std::string rest = channel.substr(session.size());
  if (rest == "_DEVICE_STATE") return "device_state_t";
  if (rest == "_FORCE_MODEL") return "force_model_t";
  if (rest == "_SHAPE") return "thread_shape_t";
  if (rest == "_SOLVER_STATUS") return "solver_status_t";
  if (rest == "_DEVICE_STATUS") return "device_status_t";
  if (rest == "_COMMAND") return "command_t";
  if (rest == "_COMMAND_REPLY") return "command_reply_t";
  return "";
}

struct Stats { double p50 = 0, p99 = 0, max = 0; size_t n = 0; };
Stats Percentiles(std::vector<double> v) {
  Stats s;
  s.n = v.size();
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  auto rank = [&](double q) { return v[std::min(v.size(), std::max<size_t>(1, size_t(std::ceil(q * v.size())))) - 1]; };
  s.p50 = rank(0.5);
  s.p99 = rank(0.99);
  s.max = v.back();
  return s;
}

// A sealed event (--encrypt) is opened with the process's read key first (--key).
template <class T>
bool Decode(const lcm::LogEvent& e, T* msg, ChannelStats* c) {
  std::string why;
  const void* data = e.data;
  int size = e.datalen;
  if (auth::IsSealed(data, static_cast<std::size_t>(size))) {
    const auto opened = auth::OpenSealed(data, static_cast<std::size_t>(size), e.channel);
    if (!opened) {
      if (c->rejected++ == 0) {
        c->first_rejection = "sealed (--encrypt) and not opened: give --key a credential of this session";
      }
      return false;
    }
    data = opened->data;
    size = static_cast<int>(opened->size);
  }
  if (messages::DecodeAndValidate(data, size, msg, &why)) return true;
  if (c->rejected++ == 0) c->first_rejection = why;
  return false;
}

std::string Fmt(const char* format, double v) {
  char b[64];
  std::snprintf(b, sizeof b, format, v);
  return b;
}

}  // namespace

std::string InferSession(const std::map<std::string, int64_t>& channel_counts) {
  std::map<std::string, int64_t> per_session;
  for (const auto& [channel, n] : channel_counts) {
    for (const char* suffix : kSuffixes) {
      const std::string s(suffix);
      if (channel.size() > s.size() &&
          channel.compare(channel.size() - s.size(), s.size(), s) == 0) {
        // Only a name of the session grammar can be a session: a channel such as
        // LAB1_';system "id"#_FORCE_MODEL is a foreign channel, counted and shown escaped.
        const std::string session = channel.substr(0, channel.size() - s.size());
        if (messages::IsValidSessionName(session)) per_session[session] += n;
      }
    }
  }
  std::string best;
  int64_t best_n = 0;
  for (const auto& [session, n] : per_session) {
    if (n > best_n) best = session, best_n = n;
  }
  return best;
}

SessionReview::SessionReview(std::string session) : session_(std::move(session)) {}

void SessionReview::Add(const lcm::LogEvent& e) {
  if (t0_us_ < 0) t0_us_ = e.timestamp;
  const double t = TimeS(e.timestamp);
  last_s_ = std::max(last_s_, t);
  auto found = channels_.find(e.channel);
  if (found == channels_.end() && channels_.size() >= kMaxListedChannels) {
    // A log with ever new channel names cannot grow the table without bound.
    unlisted_messages_++;
    unlisted_bytes_ += e.datalen;
    return;
  }
  ChannelStats& c = found != channels_.end() ? found->second : channels_[e.channel];
  if (c.messages == 0) {
    c.type = TypeOf(e.channel, session_);
    c.first_s = t;
  }
  c.messages++;
  c.bytes += e.datalen;
  c.last_s = t;
  if (c.type == "force_model_t") {
    force_model_t m;
    if (!Decode(e, &m, &c)) return;
    c.has_seq = true;
    c.seq.Add(m.seq);
    const double n = std::sqrt(m.f0[0] * m.f0[0] + m.f0[1] * m.f0[1] + m.f0[2] * m.f0[2]);
    force_.push_back({t, {m.f0[0], m.f0[1], m.f0[2]}, n, m.status, m.seq,
                      std::isfinite(m.force_error_n) ? m.force_error_n : -1.0, GraspIndex(m.grasp)});
    if (m.status == force_model_t::STATUS_SNAPPED) snap_times_s_.push_back(t);
    solve_.push_back({t, m.iterations, m.residual, m.solve_us, m.status});
    if (first_answered_pose_ < 0) first_answered_pose_ = m.device_seq;
    if (m.device_seq > last_answered_pose_) {
      answered_poses_++;
      last_answered_pose_ = m.device_seq;
    } else {
      device_seq_regressions_++;
    }
    // Round trip as the logger saw it: pose k logged -> model answering k logged.
    const auto it = pose_log_time_us_.find(m.device_seq);
    if (it != pose_log_time_us_.end()) {
      round_trip_.push_back({t, double(e.timestamp - it->second),
                             double(m.utime - m.server_receive_utime)});
    }
  } else if (c.type == "device_state_t") {
    device_state_t m;
    if (!Decode(e, &m, &c)) return;
    c.has_seq = true;
    c.seq.Add(m.seq);
    pose_log_time_us_[m.seq] = e.timestamp;
    if (pose_log_time_us_.size() > kMaxRememberedPoses) {
      pose_log_time_us_.erase(pose_log_time_us_.begin());
    }
  } else if (c.type == "thread_shape_t") {
    thread_shape_t m;
    if (!Decode(e, &m, &c)) return;
    c.has_seq = true;
    c.seq.Add(m.seq);
    if (shape_snaps_first_ < 0) shape_snaps_first_ = m.snaps;
    shape_snaps_last_ = m.snaps;
  } else if (c.type == "solver_status_t") {
    solver_status_t m;
    if (!Decode(e, &m, &c)) return;
    c.has_seq = true;
    c.seq.Add(m.seq);
    status_.push_back({t, m.method, m.iterations, m.residual, m.lambda_min, m.negative_pivots,
                       m.update_rate_hz, m.solve_us_p50, m.solve_us_p99, m.dropped_poses});
    knot_.push_back({t, m.knot, m.knot_determinant, m.contacts});
  } else if (c.type == "device_status_t") {
    device_status_t m;
    if (!Decode(e, &m, &c)) return;
    c.has_seq = true;
    c.seq.Add(m.seq);
    device_.push_back({t, m.tick_rate_hz, m.lateness_us_p50, m.lateness_us_p99,
                       m.lateness_us_max, m.model_age_ms, m.round_trip_us_p50,
                       m.round_trip_us_p99, m.force_norm_n, m.force_clamps, m.stiffness_clamps,
                       m.slew_limits, m.fades, m.snaps_felt});
  } else if (c.type == "command_t") {
    command_t m;
    Decode(e, &m, &c);
  } else if (c.type == "command_reply_t") {
    command_reply_t m;
    if (!Decode(e, &m, &c)) return;
    c.has_seq = true;
    c.seq.Add(m.seq);
  }
}

bool SessionReview::HasKnot() const {
  for (const auto& r : knot_) {
    if (!r.knot.empty() || r.contacts > 0) return true;
  }
  return false;
}

std::vector<std::string> SessionReview::WriteCsv(const std::string& dir) const {
  std::vector<std::string> written;
  auto open = [&](const std::string& name) {
    written.push_back(name);
    return std::ofstream(dir + "/" + name);
  };
  {
    auto f = open("force.csv");
    // force_error_n: "none" where the model carried none (-1), which gnuplot skips.
    f << "t_s,fx_n,fy_n,fz_n,f_norm_n,status,seq,grasp_index,force_error_n\n";
    for (const auto& r : force_) {
      f << r.t_s << ',' << r.f[0] << ',' << r.f[1] << ',' << r.f[2] << ',' << r.norm_n << ','
        << r.status << ',' << r.seq << ',' << r.grasp << ',';
      if (r.error_n >= 0.0) {
        f << r.error_n << '\n';
      } else {
        f << "none\n";
      }
    }
  }
  {
    auto f = open("snaps.csv");
    f << "t_s,f_norm_n\n";
    size_t k = 0;
    for (double t : snap_times_s_) {
      while (k + 1 < force_.size() && force_[k].t_s < t) ++k;
      f << t << ',' << (force_.empty() ? 0.0 : force_[k].norm_n) << '\n';
    }
  }
  {
    auto f = open("solve.csv");
    f << "t_s,iterations,residual,solve_us,status\n";
    for (const auto& r : solve_) {
      f << r.t_s << ',' << r.iterations << ',' << r.residual << ',' << r.solve_us << ','
        << r.status << '\n';
    }
  }
  {
    auto f = open("solver_status.csv");
    f << "t_s,method,method_index,iterations,residual,lambda_min,negative_pivots,update_rate_hz,"
         "solve_us_p50,solve_us_p99,dropped_poses\n";
    for (const auto& r : status_) {
      const int mi = r.method == "newton" ? 0 : r.method == "newton-ls" ? 1 : r.method == "higher-order" ? 2 : 3;
      f << r.t_s << ',' << Shown(r.method) << ',' << mi << ',' << r.iterations << ',' << r.residual << ','
        << r.lambda_min << ',' << r.negative_pivots << ',' << r.update_rate_hz << ','
        << r.solve_us_p50 << ',' << r.solve_us_p99 << ',' << r.dropped_poses << '\n';
    }
  }
  {
    auto f = open("knot.csv");
    f << "t_s,knot,knot_determinant,contacts\n";
    for (const auto& r : knot_) {
      f << r.t_s << ',' << (r.knot.empty() ? "-" : Shown(r.knot)) << ',' << r.determinant << ','
        << r.contacts << '\n';
    }
  }
  {
    auto f = open("device_status.csv");
    f << "t_s,tick_rate_hz,lateness_p50_us,lateness_p99_us,lateness_max_us,model_age_ms,"
         "round_trip_p50_us,round_trip_p99_us,force_norm_n,force_clamps,stiffness_clamps,"
         "slew_limits,fades,snaps_felt\n";
    for (const auto& r : device_) {
      f << r.t_s << ',' << r.tick_rate_hz << ',' << r.lateness_p50_us << ',' << r.lateness_p99_us
        << ',' << r.lateness_max_us << ',' << r.model_age_ms << ',' << r.rt_p50_us << ','
        << r.rt_p99_us << ',' << r.force_norm_n << ',' << r.force_clamps << ','
        << r.stiffness_clamps << ',' << r.slew_limits << ',' << r.fades << ',' << r.snaps_felt
        << '\n';
    }
  }
  {
    auto f = open("round_trip.csv");
    f << "t_s,loop_us,server_us\n";
    for (const auto& r : round_trip_) f << r.t_s << ',' << r.loop_us << ',' << r.server_us << '\n';
  }
  {
    auto f = open("channels.csv");
    f << "channel,type,messages,rejected,seq_first,seq_highest,missing,gaps,out_of_order\n";
    for (const auto& [name, c] : channels_) {
      f << Shown(name) << ',' << c.type << ',' << c.messages << ',' << c.rejected << ','
        << (c.has_seq ? c.seq.first() : 0) << ',' << (c.has_seq ? c.seq.highest() : 0) << ','
        << c.seq.missing() << ',' << c.seq.gap_count() << ',' << c.seq.out_of_order() << '\n';
    }
  }
  return written;
}

void SessionReview::SummaryChannels(std::ostream& s) const {
  s << "channels (messages, rate, rejected, sequence numbers):\n";
  for (const auto& [name, c] : channels_) {
    const double span = c.last_s - c.first_s;
    s << "channel " << Shown(name) << " type " << (c.type.empty() ? "-" : c.type) << " messages "
      << c.messages << " rate_hz " << Fmt("%.1f", span > 0 ? (c.messages - 1) / span : 0.0)
      << " rejected " << c.rejected;
    if (c.has_seq) {
      s << " seq " << c.seq.first() << ".." << c.seq.highest() << " missing " << c.seq.missing()
        << " gaps " << c.seq.gap_count() << " out_of_order " << c.seq.out_of_order();
    }
    s << "\n";
    if (c.rejected > 0) s << "  first rejection: " << c.first_rejection << "\n";
  }
  if (unlisted_messages_ > 0) {
    s << "channels beyond the first " << kMaxListedChannels << ": " << unlisted_messages_
      << " messages (" << unlisted_bytes_ << " bytes), not listed\n";
  }
  int invalid_names = 0;
  for (const auto& [name, c] : channels_) invalid_names += !messages::IsValidChannelName(name);
  if (invalid_names > 0) {
    s << "channel names outside the channel grammar [A-Za-z0-9_.:/-]{1,63}: " << invalid_names
      << " (shown escaped, \\xNN per byte; never taken as a session)\n";
  }
  s << "\nsequence gaps (seq after -> seq before: missing; first "
    << SequenceTracker::kMaxListedGaps << " per channel):\n";
  bool any_gap = false;
  for (const auto& [name, c] : channels_) {
    for (const auto& g : c.seq.gaps()) {
      s << "gap " << Shown(name) << " " << g.after << " -> " << g.before << ": " << g.Missing() << "\n";
      any_gap = true;
    }
  }
  if (!any_gap) s << "(none)\n";
}

void SessionReview::SummaryForce(std::ostream& s) const {
  s << "\nforce:\n";
  if (force_.empty()) {
    s << "no force models in the log\n";
  } else {
    const auto mx = std::max_element(force_.begin(), force_.end(),
                                     [](const ForceRow& a, const ForceRow& b) { return a.norm_n < b.norm_n; });
    s << "max_force_n: " << Fmt("%.4f", mx->norm_n) << " at t_s " << Fmt("%.3f", mx->t_s) << "\n";
    SummaryForceError(s);
  }
  s << "snaps: " << snap_times_s_.size() << " (force models with STATUS_SNAPPED)";
  if (shape_snaps_last_ >= 0) s << ", shapes count " << shape_snaps_last_ - shape_snaps_first_;
  s << "\n";
  for (size_t i = 0; i < snap_times_s_.size() && i < 20; ++i) {
    s << "  snap at t_s " << Fmt("%.3f", snap_times_s_[i]) << "\n";
  }

  if (first_answered_pose_ >= 0) {
    const int64_t span = last_answered_pose_ - first_answered_pose_ + 1;
    s << "latest_wins: models answer " << answered_poses_ << " poses of seq "
      << first_answered_pose_ << ".." << last_answered_pose_ << ", skipped_poses "
      << span - answered_poses_ << ", device_seq_regressions " << device_seq_regressions_ << "\n";
  }
}

int SessionReview::GraspIndex(const std::string& grasp) {
  for (size_t i = 0; i < grasps_.size(); ++i)
    if (grasps_[i] == grasp) return static_cast<int>(i);
  if (grasps_.size() < kMaxGrasps) grasps_.push_back(grasp);
  return static_cast<int>(grasps_.size()) - 1;
}

bool SessionReview::HasForceError() const {
  for (const auto& r : force_)
    if (r.error_n >= 0.0) return true;
  return false;
}

// The certified force error per grasp: median and max over the models that carry one, and
// how many carry none (-1).
void SessionReview::SummaryForceError(std::ostream& s) const {
  for (size_t g = 0; g < grasps_.size(); ++g) {
    std::vector<double> errors;
    size_t models = 0;
    for (const auto& r : force_) {
      if (r.grasp != static_cast<int>(g)) continue;
      ++models;
      if (r.error_n >= 0.0) errors.push_back(r.error_n);
    }
    const std::string name = grasps_[g].empty() ? "-" : Shown(grasps_[g]);
    s << "force_error_n (certified) grasp " << name << ": ";
    if (errors.empty()) {
      s << "none";
    } else {
      const Stats e = Percentiles(errors);
      s << "p50 " << Fmt("%.3g", e.p50) << " max " << Fmt("%.3g", e.max) << " N";
    }
    s << "; none on " << models - errors.size() << " of " << models << " models\n";
  }
}

void SessionReview::SummarySolver(std::ostream& s) const {
  s << "\nsolver:\n";
  if (!solve_.empty()) {
    std::vector<double> it, res, us;
    for (const auto& r : solve_) {
      it.push_back(r.iterations);
      res.push_back(r.residual);
      us.push_back(r.solve_us);
    }
    const Stats si = Percentiles(it), sr = Percentiles(res), su = Percentiles(us);
    s << "iterations p50 " << si.p50 << " max " << si.max << "; residual p50 "
      << Fmt("%.3g", sr.p50) << " max " << Fmt("%.3g", sr.max) << "; solve_us p50 " << su.p50
      << " p99 " << su.p99 << " max " << su.max << "\n";
  }
  if (!status_.empty()) {
    std::string methods;
    for (const auto& r : status_) {
      const std::string m = Shown(r.method);
      if (methods.find(m) == std::string::npos) methods += (methods.empty() ? "" : ", ") + m;
    }
    s << "methods: " << methods << "; dropped_poses (latest wins) " << status_.back().dropped_poses
      << "\n";
  }
  if (solve_.empty() && status_.empty()) s << "no solver messages in the log\n";
}

void SessionReview::SummaryKnot(std::ostream& s) const {
  s << "\nknot:\n";
  if (!HasKnot()) {
    s << "no knot type or contacts in the solver status\n";
  } else {
    // The knot type over time: each change, with its determinant (first 20).
    s << "knot_changes:";
    std::string last = "\x01";
    int listed = 0;
    for (const auto& r : knot_) {
      if (r.knot == last) continue;
      last = r.knot;
      if (++listed > 20) {
        s << " ...";
        break;
      }
      s << " " << Fmt("%.3f", r.t_s) << " " << (r.knot.empty() ? "-" : Shown(r.knot)) << " (det "
        << r.determinant << ")";
    }
    int max_contacts = 0;
    for (const auto& r : knot_) max_contacts = std::max(max_contacts, r.contacts);
    s << "\nknot_last: " << (knot_.back().knot.empty() ? "-" : Shown(knot_.back().knot))
      << "; contacts max " << max_contacts << " last " << knot_.back().contacts << "\n";
  }
}

void SessionReview::SummaryDevice(std::ostream& s) const {
  s << "\ndevice:\n";
  if (device_.empty()) {
    s << "no device status in the log\n";
  } else {
    const DeviceRow& first = device_.front();
    const DeviceRow& last = device_.back();
    double late_max = 0, age_max = 0;
    for (const auto& r : device_) {
      late_max = std::max(late_max, r.lateness_max_us);
      age_max = std::max(age_max, r.model_age_ms);
    }
    s << "tick_rate_hz last " << Fmt("%.1f", last.tick_rate_hz) << "; lateness max_us "
      << Fmt("%.1f", late_max) << "; model_age max_ms " << Fmt("%.2f", age_max) << "\n";
    s << "clamps: force " << last.force_clamps - first.force_clamps << " stiffness "
      << last.stiffness_clamps - first.stiffness_clamps << " slew " << last.slew_limits - first.slew_limits
      << " fade_ticks " << last.fades - first.fades << " (counted over the log; totals since device start: force "
      << last.force_clamps << " stiffness " << last.stiffness_clamps << ")\n";
  }
  if (!round_trip_.empty()) {
    std::vector<double> loop, server;
    for (const auto& r : round_trip_) {
      loop.push_back(r.loop_us);
      server.push_back(r.server_us);
    }
    const Stats l = Percentiles(loop), sv = Percentiles(server);
    s << "round_trip_us (pose logged -> model logged) p50 " << Fmt("%.0f", l.p50) << " p99 "
      << Fmt("%.0f", l.p99) << " max " << Fmt("%.0f", l.max) << "; server_us p50 "
      << Fmt("%.0f", sv.p50) << " p99 " << Fmt("%.0f", sv.p99) << "\n";
  }
}

std::string SessionReview::Summary(const std::string& log_path, const LogReadStats& read,
                                   const std::vector<std::string>& plots,
                                   const std::vector<std::string>& notes) const {
  std::ostringstream s;
  s << "snapthread session report\n";
  s << "log: " << log_path << " (" << read.file_bytes << " bytes)\n";
  s << "session: " << (session_.empty() ? "(none found)" : session_) << "\n";
  s << "read: " << (read.Partial() ? "PARTIAL" : "COMPLETE") << ", " << read.events
    << " events, " << read.skipped_bytes << " bytes unreadable\n";
  s << "duration_s: " << Fmt("%.3f", last_s_) << "\n\n";

  SummaryChannels(s);
  SummaryForce(s);
  SummarySolver(s);
  SummaryKnot(s);
  SummaryDevice(s);

  s << "\nplots:";
  for (const auto& p : plots) s << " " << p;
  s << (plots.empty() ? " (none)\n" : "\n");
  if (!read.warnings.empty() || !notes.empty()) {
    s << "\nwarnings:\n";
    for (const auto& w : read.warnings) s << "WARNING: " << w << "\n";
    for (const auto& n : notes) s << "note: " << n << "\n";
  }
  return s.str();
}

}  // namespace snapthread::report
