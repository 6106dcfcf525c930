#include "replay_feed.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include <lcm/lcm-cpp.hpp>

#include "json_writer.h"
#include "message_json.h"
#include "messages/validate.h"
#include "observer_check.h"

namespace snapthread::web {
namespace {

constexpr const char* kSuffixes[] = {"_SHAPE", "_FORCE_MODEL", "_SOLVER_STATUS", "_DEVICE_STATUS"};

// The kind of a channel named <session>_<suffix>, and its session; false for others.
bool Classify(const std::string& channel, FeedKind* kind, std::string* session) {
  for (int i = 0; i < 4; ++i) {
    const std::string suffix = kSuffixes[i];
    if (channel.size() > suffix.size() &&
        channel.compare(channel.size() - suffix.size(), suffix.size(), suffix) == 0) {
      *kind = static_cast<FeedKind>(i);
      *session = channel.substr(0, channel.size() - suffix.size());
      return true;
    }
  }
  return false;
}

template <class Msg>
bool Decode(const lcm::LogEvent& e, Msg* msg) {
  return messages::DecodeAndValidate(e.data, e.datalen, msg, nullptr);
}

// Whether the decoded message of `e` is genuine (observer_check.h).
template <class Msg>
bool Genuine(const lcm::LogEvent& e, const Msg& msg, const auth::PublicKey& server_key) {
  return viewer::CheckObserved(e.data, static_cast<std::size_t>(e.datalen), e.channel, msg, server_key) ==
         viewer::ObserverVerdict::kAccepted;
}

// The session of the log's first shape channel ("" when none).
std::string FirstShapeSession(const std::string& path) {
  lcm::LogFile log(path, "r");
  if (!log.good()) return "";
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    FeedKind kind;
    std::string session;
    if (Classify(e->channel, &kind, &session) && kind == FeedKind::kShape) return session;
  }
  return "";
}

}  // namespace

ReplayFeed::ReplayFeed(const std::string& path, const std::string& session,
                       const auth::PublicKey& server_key, PublishFn publish)
    : publish_(std::move(publish)), session_(session), server_key_(server_key) {
  if (session_.empty()) session_ = FirstShapeSession(path);
  lcm::LogFile log(path, "r");
  if (!log.good()) throw std::runtime_error("cannot read the log file " + path);
  int64_t first_us = -1;
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    FeedKind kind;
    std::string channel_session;
    if (!Classify(e->channel, &kind, &channel_session)) continue;
    if (channel_session != session_) continue;
    if (first_us < 0) first_us = e->timestamp;
    const int64_t t_us = e->timestamp - first_us;
    bool skip = false;
    std::string json = Vet(*e, kind, t_us, &skip);
    if (skip || json.empty()) continue;
    counts_.received[Index(kind)]++;
    events_.push_back({t_us, kind, std::make_shared<const std::string>(std::move(json))});
  }
  if (shape_events_.empty()) {
    throw std::runtime_error(path + " holds no valid thread_shape_t of " +
                             (session_.empty() ? std::string("any session") : "session " + session_) +
                             " signed by the server of --key" +
                             (counts_.auth_rejected > 0
                                  ? " (" + std::to_string(counts_.auth_rejected) +
                                        " messages refused: is it the log of another session's server?)"
                                  : std::string()));
  }
}

std::string ReplayFeed::Vet(const lcm::LogEvent& e, FeedKind kind, int64_t t_us, bool* skip) {
  const auto vet = [&](auto* m) -> bool {
    if (!Decode(e, m)) {
      counts_.malformed++;
      return false;
    }
    if (!Genuine(e, *m, server_key_)) {
      counts_.auth_rejected++;
      return false;
    }
    return true;
  };
  if (kind == FeedKind::kShape) {
    thread_shape_t m;
    if (!vet(&m) || m.num_nodes <= 0) return "";
    shape_events_.push_back(static_cast<int64_t>(events_.size()));
    last_seq_ = m.seq;
    return ShapeJson(m, DrawsSmooth(m.model));
  }
  if (kind == FeedKind::kForceModel) {
    // Models the server did not sign are the device's, not the observers'.
    *skip = viewer::SignaturesAbsent(e.data, static_cast<std::size_t>(e.datalen)) ||
            1e-6 * t_us - last_force_s_ < kForceModelMinIntervalS;
    force_model_t m;
    if (*skip || !vet(&m)) return "";
    last_force_s_ = 1e-6 * t_us;
    return ForceModelJson(m);
  }
  if (kind == FeedKind::kSolverStatus) {
    solver_status_t m;
    return vet(&m) ? SolverStatusJson(m) : "";
  }
  device_status_t m;
  return vet(&m) ? DeviceStatusJson(m) : "";
}

ReplayFeed::~ReplayFeed() { Stop(); }

void ReplayFeed::Start() {
  if (running_.exchange(true)) return;
  thread_ = std::thread(&ReplayFeed::Loop, this);
}

void ReplayFeed::Stop() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    running_ = false;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

bool ReplayFeed::Command(const std::string& command) {
  std::istringstream in(command);
  std::string verb;
  in >> verb;
  double value = 0.0;
  const bool has_value = static_cast<bool>(in >> value) && std::isfinite(value);
  std::lock_guard<std::mutex> lock(mutex_);
  if (verb == "play" && !has_value) {
    if (next_ >= events_.size()) {  // at the end: play again from the start
      t_us_ = 0;
      next_ = 0;
      shapes_played_ = 0;
    }
    paused_ = false;
  } else if (verb == "pause" && !has_value) {
    paused_ = true;
  } else if (verb == "seek" && has_value) {
    const int64_t t = static_cast<int64_t>(1e6 * std::clamp(value, 0.0, 1e-6 * events_.back().t_us));
    PlayTo(t, true);
  } else if (verb == "speed" && has_value && value > 0) {
    speed_ = std::min(value, kMaxSpeed);
  } else {
    return false;
  }
  position_changed_ = true;
  wake_.notify_all();
  return true;
}

void ReplayFeed::PlayTo(int64_t t_us, bool latest_only) {
  const auto target = std::upper_bound(events_.begin(), events_.end(), t_us,
                                       [](int64_t t, const Event& e) { return t < e.t_us; });
  const size_t end = static_cast<size_t>(target - events_.begin());
  if (latest_only) {
    // The state at t: the last event of each kind before it.
    bool seen[kFeedKinds] = {};
    for (size_t i = end; i-- > 0;) {
      if (seen[Index(events_[i].kind)]) continue;
      seen[Index(events_[i].kind)] = true;
      publish_(events_[i].kind, events_[i].json);
    }
    shapes_played_ = std::upper_bound(shape_events_.begin(), shape_events_.end(),
                                      static_cast<int64_t>(end) - 1) - shape_events_.begin();
  } else {
    for (size_t i = next_; i < end; ++i) {
      if (events_[i].kind == FeedKind::kShape) shapes_played_++;
      publish_(events_[i].kind, events_[i].json);
    }
  }
  next_ = end;
  t_us_ = t_us;
}

ReplayPosition ReplayFeed::PositionLocked() const {
  ReplayPosition p;
  p.t_s = 1e-6 * t_us_;
  p.duration_s = 1e-6 * events_.back().t_us;
  p.paused = paused_;
  p.at_end = next_ >= events_.size();
  p.speed = speed_;
  p.shape_index = shapes_played_;
  p.shape_count = static_cast<int64_t>(shape_events_.size());
  p.last_seq = last_seq_;
  return p;
}

ReplayPosition ReplayFeed::position() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return PositionLocked();
}

FeedCounts ReplayFeed::counts() const { return counts_; }

void ReplayFeed::PublishPosition() {
  const ReplayPosition p = PositionLocked();
  JsonWriter w;
  w.BeginObject().String("type", "replay").Number("t_s", p.t_s).Number("duration_s", p.duration_s);
  w.Bool("paused", p.paused).Bool("at_end", p.at_end).Number("speed", p.speed);
  w.Int("shape_index", p.shape_index).Int("shape_count", p.shape_count).Int("last_seq", p.last_seq);
  publish_(FeedKind::kReplay, std::make_shared<const std::string>(w.EndObject().Take()));
  position_changed_ = false;
}

void ReplayFeed::Loop() {
  using Clock = std::chrono::steady_clock;
  constexpr auto kStep = std::chrono::milliseconds(5);
  constexpr auto kPositionEvery = std::chrono::milliseconds(100);
  std::unique_lock<std::mutex> lock(mutex_);
  auto last = Clock::now();
  auto last_position = last;
  while (running_) {
    wake_.wait_for(lock, kStep);
    const auto now = Clock::now();
    const double dt_s = std::chrono::duration<double>(now - last).count();
    last = now;
    if (!paused_ && next_ < events_.size()) {
      const int64_t t = t_us_ + static_cast<int64_t>(1e6 * dt_s * speed_);
      PlayTo(std::min(t, events_.back().t_us), false);
      if (next_ >= events_.size()) {
        paused_ = true;  // stay on the last frame
        position_changed_ = true;
      }
    }
    if (position_changed_ || now - last_position >= kPositionEvery) {
      PublishPosition();
      last_position = now;
    }
  }
}

}  // namespace snapthread::web
