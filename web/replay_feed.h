// The bridge's replay mode (`snapthread-web --log FILE`): reads a session recorded by
// snapthread-logger or lcm-logger (lcm::LogFile), keeps the session's shapes, force
// models and statuses as the JSON the page reads, and plays them to `publish` at the
// recorded pace times a speed, with pause, seek and speed commands from the page.
// The log is read from disk as recorded: messages are validated (malformed ones skipped
// and counted) and checked as the live feed checks them (viewer/observer_check.h: the
// server's signature, a device's certificate and signature; refused ones skipped and
// counted, force models the server did not sign skipped uncounted), so an observer
// credential reviews a log; seeking back is allowed (no freshness).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "auth/key_id.h"
#include "client_pacer.h"
#include "live_feed.h"

namespace snapthread::web {

struct ReplayPosition {
  double t_s = 0.0;           // log time played, seconds from the first message
  double duration_s = 0.0;    // log time of the last message
  bool paused = false;
  bool at_end = false;        // played to the last message
  double speed = 1.0;
  int64_t shape_index = 0;    // shapes played so far (== shape_count at the end)
  int64_t shape_count = 0;    // shapes in the log
  int64_t last_seq = -1;      // seq of the last shape in the log
};

class ReplayFeed {
 public:
  // Force models closer together than this in log time are skipped: the page charts them
  // at its 60 Hz, and a 1 kHz session would otherwise hold minutes of them in memory.
  static constexpr double kForceModelMinIntervalS = 1.0 / 120.0;
  static constexpr double kMaxSpeed = 64.0;

  // Reads the whole log, keeping what `server_key` (the server's public key) vouches for;
  // `session` "" takes the session of the first shape channel. Throws std::runtime_error
  // when the file cannot be read or holds no genuine shape of a session.
  ReplayFeed(const std::string& path, const std::string& session, const auth::PublicKey& server_key,
             PublishFn publish);
  ~ReplayFeed();
  ReplayFeed(const ReplayFeed&) = delete;
  ReplayFeed& operator=(const ReplayFeed&) = delete;

  void Start();
  void Stop();
  // A page's command: "play", "pause", "seek SECONDS", "speed FACTOR". False (ignored)
  // for anything else.
  bool Command(const std::string& command);
  ReplayPosition position() const;
  FeedCounts counts() const;
  const std::string& session() const { return session_; }

 private:
  struct Event {
    int64_t t_us;  // log time from the first kept event
    FeedKind kind;
    Text json;
  };
  void Loop();
  // Publishes events up to `t_us` (lock held); with `latest_only` only the last of each
  // kind before it (a seek).
  void PlayTo(int64_t t_us, bool latest_only);
  void PublishPosition();
  // The JSON of one logged message of `kind` when it is valid and genuine, else "" (and
  // counted); `skip` set for a force model not meant for observers or shown too soon.
  std::string Vet(const lcm::LogEvent& e, FeedKind kind, int64_t t_us, bool* skip);
  ReplayPosition PositionLocked() const;

  PublishFn publish_;
  std::string session_;
  auth::PublicKey server_key_;
  double last_force_s_ = -1e9;
  std::vector<Event> events_;
  std::vector<int64_t> shape_events_;  // indices of the shapes in events_
  int64_t last_seq_ = -1;
  FeedCounts counts_;
  std::thread thread_;
  std::atomic<bool> running_{false};

  mutable std::mutex mutex_;  // guards everything below
  std::condition_variable wake_;
  int64_t t_us_ = 0;
  size_t next_ = 0;  // first event not played yet
  int64_t shapes_played_ = 0;
  bool paused_ = false;
  double speed_ = 1.0;
  bool position_changed_ = true;
};

}  // namespace snapthread::web
