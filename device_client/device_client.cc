#include "device_client.h"

#include <chrono>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <thread>
#include <utility>

#include <spdlog/spdlog.h>

#include "auth/message_mac.h"
#include "messages/validate.h"
#include "realtime/clock.h"

namespace snapthread::device {
namespace {

double Seconds(int64_t us) { return 1e-6 * static_cast<double>(us); }

void WriteTraceHeader(std::FILE* f) {
  std::fputs("t_s,seq,x_m,y_m,z_m,fx_n,fy_n,fz_n,model_age_ms,model_status,clamped,fading,"
             "qw,qx,qy,qz,tx_nm,ty_nm,tz_nm\n", f);
}

void WriteTraceRow(std::FILE* f, const TraceRow& r, int64_t start_us) {
  std::fprintf(f, "%.6f,%lld,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.3f,%d,%d,%d,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g\n",
               Seconds(r.utime_us - start_us), static_cast<long long>(r.tick), r.position_m[0],
               r.position_m[1], r.position_m[2], r.force_n[0], r.force_n[1], r.force_n[2],
               r.model_age_ms, static_cast<int>(r.model_status), r.clamped ? 1 : 0,
               r.fading ? 1 : 0, r.orientation[0], r.orientation[1], r.orientation[2],
               r.orientation[3], r.torque_nm[0], r.torque_nm[1], r.torque_nm[2]);
}

std::FILE* OpenTrace(const std::string& path) {
  if (path.empty()) return nullptr;
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (f == nullptr) throw std::runtime_error("--trace: cannot write " + path);
  WriteTraceHeader(f);
  return f;
}

int CloseFile(std::FILE* f) { return f != nullptr ? std::fclose(f) : 0; }

}  // namespace

DeviceClient::DeviceClient(HapticDevice* device, DeviceTransport* transport,
                           DeviceClientConfig config)
    : device_(device),
      transport_(transport),
      config_(std::move(config)),
      safety_(config_.limits, config_.device_has_orientation, config_.device_torque_output),
      models_(std::make_unique<ModelSlot>()),
      poses_(std::make_unique<PoseRing>()),
      trace_ring_(std::make_unique<TraceRing>()),
      lateness_(std::make_unique<LatenessRing>()),
      trace_file_(OpenTrace(config_.trace_file), &CloseFile),
      channels_(config_.session),
      sent_poses_(std::make_unique<auth::PoseEchoWindow>()),
      receiver_(config_.limits, models_.get(),
                ModelAuth{config_.keys, channels_.force_model, channels_.solver_status,
                                    sent_poses_.get()}),
      tick_(device_, &safety_, models_.get(), poses_.get(),
            trace_file_ ? trace_ring_.get() : nullptr, lateness_.get(), config_.tick),
      loop_(&tick_, config_.loop) {
  state_msg_.device_id = config_.device_id;
  if (config_.snap_ahead) tick_.SetSnapAhead(&snap_ahead_);
  state_msg_.grasp = config_.grasp;
  receiver_.SetGrasp(config_.grasp);
  start_us_ = Now();
  last_status_us_ = last_log_us_ = start_us_;
}

DeviceClient::~DeviceClient() { Stop(); }

int64_t DeviceClient::Now() const {
  return config_.clock != nullptr ? config_.clock() : realtime::MonotonicMicros();
}

void DeviceClient::Start(std::string* notes) {
  stop_threads_.store(false);
  start_us_ = Now();
  last_status_us_ = last_log_us_ = start_us_;
  receive_thread_ = std::thread([this] {
    while (!stop_threads_.load()) {
      // < 0: the transport failed; do not spin (the watchdog fades the force meanwhile).
      if (Receive(config_.receive_wait_ms) < 0) {
        std::this_thread::sleep_for(std::chrono::milliseconds(config_.receive_wait_ms));
      }
    }
  });
  io_thread_ = std::thread([this] {
    while (!stop_threads_.load()) {
      Service(Now());
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    }
  });
  loop_.Start(notes);
  started_ = true;
}

bool DeviceClient::FadeOut(double timeout_s) {
  safety_.RequestFadeOut();
  if (!started_) return true;
  const int64_t deadline_us = Now() + static_cast<int64_t>(1e6 * timeout_s);
  while (Now() < deadline_us) {
    if (tick_.counters().force_norm_n.load() == 0.0) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  return tick_.counters().force_norm_n.load() == 0.0;
}

void DeviceClient::Stop() {
  if (!started_) return;
  started_ = false;
  loop_.Stop();
  end_us_ = Now();
  final_force_n_ = tick_.counters().force_norm_n.load();
  const double zero[3] = {0.0, 0.0, 0.0};
  device_->Command(zero, zero);
  stop_threads_.store(true);
  if (io_thread_.joinable()) io_thread_.join();
  if (receive_thread_.joinable()) receive_thread_.join();
  Drain();
  if (trace_file_) std::fflush(trace_file_.get());
}

void DeviceClient::Tick(int64_t now_us, int64_t lateness_us) { tick_.Tick(now_us, lateness_us); }

int DeviceClient::Receive(int wait_ms) {
  const int n = transport_->PollForceModels(wait_ms, [this](const void* data, int size) {
    receiver_.Receive(data, size, Now());
  });
  transport_->PollSolverStatus(
      [this](const void* data, int size) { receiver_.ReceiveStatus(data, size, Now()); });
  return n;
}

bool DeviceClient::SignPose() {
  if (config_.keys == nullptr) return true;
  // Epoch 0 until an authenticated status was heard: the server refuses such poses and
  // no model can answer them, so the device stays in its fade.
  const int64_t epoch = receiver_.epoch();
  if (!auth::Sign(&state_msg_, channels_.device_state, epoch, auth_seq_.Next(),
                  config_.keys->current().tagger())) {
    return false;
  }
  // Before it leaves: a model answering it may arrive before Publish returns.
  sent_poses_->Record(epoch, state_msg_.seq, state_msg_.utime);
  return true;
}

bool DeviceClient::SignStatus(device_status_t* st) {
  if (config_.keys == nullptr) return true;
  // One set for the whole status: a reload between the fields and the tag would
  // certify one key and sign with another.
  const auth::KeySet& keys = config_.keys->current();
  const auth::PublicKey* pk = keys.device_public_key();
  const auth::DeviceCertificateBytes* cert = keys.device_certificate();
  const auth::Tagger* tagger = keys.device_status_tagger();
  if (pk == nullptr || cert == nullptr || tagger == nullptr) return false;
  std::memcpy(st->device_public_key, pk->data(), sizeof st->device_public_key);
  std::memcpy(st->device_certificate, cert->data(), sizeof st->device_certificate);
  return auth::Sign(st, channels_.device_status, receiver_.epoch(), auth_seq_.Next(), *tagger);
}

void DeviceClient::Drain() {
  PoseToPublish p;
  while (poses_->TryPop(&p)) {
    state_msg_.utime = p.utime_us;
    state_msg_.seq = p.seq;
    for (int k = 0; k < 3; ++k) state_msg_.position[k] = p.position_m[k];
    for (int k = 0; k < 4; ++k) state_msg_.orientation[k] = p.orientation[k];
    state_msg_.buttons = p.buttons;
    state_msg_.snap_fold_id = p.snap_fold_id;
    // The servo already refused bad positions; this also catches a backend's bad
    // orientation, so the server never receives a pose it would have to reject.
    if (!messages::Validate(state_msg_, nullptr) || !SignPose()) {
      invalid_poses_unpublished_.fetch_add(1);
    } else if (transport_->PublishDeviceState(state_msg_)) {
      poses_published_.fetch_add(1);
    } else {
      publish_failures_.fetch_add(1);
    }
  }
  TraceRow r;
  while (trace_ring_->TryPop(&r)) {
    if (trace_file_) WriteTraceRow(trace_file_.get(), r, start_us_);
  }
  int32_t l;
  while (lateness_->TryPop(&l)) {
    lateness_window_.Push(l);
    lateness_run_.Push(l);
    if (l > lateness_max_us_) lateness_max_us_ = l;
  }
}

void DeviceClient::Service(int64_t now_us) {
  Drain();
  MaybeReport(now_us);
}

void DeviceClient::MaybeReport(int64_t now_us) {
  if (now_us - last_status_us_ < config_.status_period_us) return;
  const uint64_t ticks = tick_.counters().ticks.load();
  const double rate =
      static_cast<double>(ticks - last_status_ticks_) / Seconds(now_us - last_status_us_);
  device_status_t st = BuildStatus(now_us, rate, status_seq_++);
  if (messages::Validate(st, nullptr) && SignStatus(&st) && !transport_->PublishDeviceStatus(st)) {
    publish_failures_.fetch_add(1);
  }
  last_status_ticks_ = ticks;
  last_status_us_ = now_us;
  if (config_.log_period_us > 0 && now_us - last_log_us_ >= config_.log_period_us) {
    const auto lat = lateness_window_.Compute();
    const auto rt = receiver_.RoundTrip(false);
    spdlog::info("device: {:.0f} Hz, lateness p50/p99/max {:.0f}/{:.0f}/{:.0f} us, "
                 "round trip p50/p99 {:.0f}/{:.0f} us, models {} (+{} rejected), |F| {:.3f} N, "
                 "clamps {}, slew {}, fade ticks {}, snaps {}",
                 rate, lat.p50, lat.p99, lat.max, rt.p50, rt.p99, receiver_.received(),
                 receiver_.rejected(), tick_.counters().force_norm_n.load(),
                 safety_.counters().force_clamps.load(), safety_.counters().slew_limits.load(),
                 safety_.counters().fade_ticks.load(), receiver_.snaps_felt());
    last_log_us_ = now_us;
  }
}

device_status_t DeviceClient::BuildStatus(int64_t now_us, double tick_rate_hz, int64_t seq) const {
  device_status_t st{};
  st.utime = now_us;
  st.seq = seq;
  st.device_id = config_.device_id;
  st.grasp = config_.grasp;
  st.tick_rate_hz = tick_rate_hz;
  const auto lat = lateness_window_.Compute();
  st.lateness_us_p50 = lat.p50;
  st.lateness_us_p99 = lat.p99;
  st.lateness_us_max = lat.max;
  const int64_t rx = tick_.counters().last_model_receive_us.load();
  st.model_age_ms = rx >= 0 ? 1e-3 * static_cast<double>(now_us - rx) : -1.0;
  const auto rt = receiver_.RoundTrip(false);
  st.round_trip_us_p50 = rt.p50;
  st.round_trip_us_p99 = rt.p99;
  st.force_norm_n = tick_.counters().force_norm_n.load();
  st.ticks = static_cast<int64_t>(tick_.counters().ticks.load());
  st.models_received = static_cast<int64_t>(receiver_.received());
  st.models_rejected = static_cast<int64_t>(receiver_.rejected());
  st.force_clamps = static_cast<int64_t>(safety_.counters().force_clamps.load());
  st.stiffness_clamps = static_cast<int64_t>(receiver_.stiffness_clamps());
  st.slew_limits = static_cast<int64_t>(safety_.counters().slew_limits.load());
  st.fades = static_cast<int64_t>(safety_.counters().fade_ticks.load());
  st.snaps_felt = static_cast<int64_t>(receiver_.snaps_felt());
  st.snap_ahead_switches = static_cast<int64_t>(snap_ahead_.switches());
  return st;
}

DeviceClientSummary DeviceClient::Summary(int64_t now_us) const {
  DeviceClientSummary s;
  const int64_t end_us = end_us_ >= 0 ? end_us_ : now_us;
  s.duration_s = Seconds(end_us - start_us_);
  s.ticks = tick_.counters().ticks.load();
  s.tick_rate_hz = s.duration_s > 0.0 ? static_cast<double>(s.ticks) / s.duration_s : 0.0;
  s.lateness_us = lateness_run_.Compute();
  s.lateness_us_max = lateness_max_us_;
  s.round_trip_us = receiver_.RoundTrip(true);
  s.models_received = receiver_.received();
  s.models_rejected = receiver_.rejected();
  s.invalid_models = receiver_.invalid_models();
  const SafetyCounters& sc = safety_.counters();
  s.poses_rejected = sc.poses_rejected.load();
  s.force_clamps = sc.force_clamps.load();
  s.stiffness_clamps = receiver_.stiffness_clamps();
  s.slew_limits = sc.slew_limits.load();
  s.fade_ticks = sc.fade_ticks.load();
  s.snaps_felt = receiver_.snaps_felt();
  s.snap_ahead_switches = snap_ahead_.switches();
  s.statuses_accepted = receiver_.statuses_accepted();
  s.statuses_rejected = receiver_.statuses_rejected();
  s.nonfinite_outputs = sc.nonfinite_outputs.load();
  s.torque_clamps = sc.torque_clamps.load();
  s.torque_slew_limits = sc.torque_slew_limits.load();
  s.wrench_models = receiver_.wrench_models();
  s.overruns = loop_.overruns();
  s.read_failures = tick_.counters().read_failures.load();
  s.pose_ring_drops = poses_->dropped();
  s.trace_ring_drops = trace_ring_->dropped();
  s.invalid_poses_unpublished = invalid_poses_unpublished_.load();
  s.publish_failures = publish_failures_.load();
  s.poses_published = poses_published_.load();
  s.max_force_n = safety_.max_force_n();
  s.final_force_n = final_force_n_;
  s.realtime = loop_.realtime_active();
  return s;
}

}  // namespace snapthread::device
