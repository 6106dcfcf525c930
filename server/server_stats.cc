#include "server_stats.h"

#include <chrono>

#include <spdlog/spdlog.h>

namespace snapthread::server {
namespace {

constexpr int64_t kLogPeriodUs = 1000000;  // rate limit for repeated warnings: 1 per second

}  // namespace

int64_t SteadyMicros() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

bool ShouldLog(std::atomic<int64_t>* last) {
  const int64_t now = SteadyMicros();
  int64_t prev = last->load(std::memory_order_relaxed);
  if (now - prev < kLogPeriodUs && prev != 0) return false;
  return last->compare_exchange_strong(prev, now);
}

void CountRejection(ServerCounters* counters, const std::string& channel, const std::string& why) {
  const int64_t total = counters->rejected_messages.fetch_add(1) + 1;
  if (ShouldLog(&counters->last_reject_log_us)) {
    spdlog::warn("server: dropped a bad message on {}: {} ({} rejected so far)", channel, why,
                 total);
  }
}

void ServerCounters::CopyTo(ServerStats* s) const {
  s->poses_received = poses_received.load();
  s->updates = updates.load();
  s->invalid_models = invalid_models.load();
  s->snaps = snaps.load();
  s->dropped_poses = dropped_poses.load();
  s->rejected_messages = rejected_messages.load();
  s->refusals = refusals.Format();
  s->commands_applied = commands_applied.load();
  s->commands_refused = commands_refused.load();
  s->shapes_published = shapes_published.load();
  s->statuses_published = statuses_published.load();
  s->publish_failures = publish_failures.load();
}

void ServerInfo::Set(const std::string& scene, const std::string& method,
                     const std::string* command) {
  std::lock_guard<std::mutex> lock(mutex_);
  scene_name_ = scene;
  method_name_ = method;
  if (command != nullptr) last_command_message_ = *command;
}

void ServerInfo::RecordSolve(double solve_us) {
  const int64_t now_us = SteadyMicros();
  std::lock_guard<std::mutex> lock(mutex_);
  run_window_.Push(solve_us);
  if (first_update_us_ == 0) first_update_us_ = now_us;
  last_update_us_ = now_us;
}

void ServerInfo::RecordCheckpointOffer(double us) {
  std::lock_guard<std::mutex> lock(mutex_);
  checkpoint_offer_us_.Push(us);
}

void ServerInfo::CopyTo(ServerStats* s, bool checkpoints) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const realtime::PercentileSummary window = run_window_.Compute();
  s->solve_us_p50 = window.p50;
  s->solve_us_p99 = window.p99;
  const double span_s = 1e-6 * static_cast<double>(last_update_us_ - first_update_us_);
  s->update_rate_hz = (window.count > 1 && span_s > 0.0)
                          ? static_cast<double>(s->updates - 1) / span_s
                          : 0.0;
  s->scene = scene_name_;
  s->method = method_name_;
  s->last_command_message = last_command_message_;
  if (checkpoints) {
    const realtime::PercentileSummary offer = checkpoint_offer_us_.Compute();
    s->checkpoint_offer_us_p50 = offer.p50;
    s->checkpoint_offer_us_p99 = offer.p99;
  }
}

}  // namespace snapthread::server
