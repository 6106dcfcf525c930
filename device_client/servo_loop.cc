#include "servo_loop.h"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <time.h>

#include <chrono>
#include <cmath>
#include <cstring>

#include "realtime/clock.h"

namespace snapthread::device {

ServoTick::ServoTick(HapticDevice* device, ForceSafety* safety, ModelSlot* models,
                     PoseRing* poses, TraceRing* trace, LatenessRing* lateness,
                     ServoTickOptions options)
    : device_(device),
      safety_(safety),
      models_(models),
      poses_(poses),
      trace_(trace),
      lateness_(lateness),
      options_(options) {
  if (options_.publish_divisor < 1) options_.publish_divisor = 1;
  if (options_.trace_divisor < 1) options_.trace_divisor = 1;
}

void ServoTick::Tick(int64_t now_us, int64_t lateness_us) {
  const bool read_ok = device_->Read(&state_);
  if (!read_ok) counters_.read_failures.fetch_add(1, std::memory_order_relaxed);

  const LocalModel* model = models_->Latest();  // wait-free
  if (snap_ahead_ != nullptr && read_ok)
    model = snap_ahead_->Select(model, state_.position_m, state_.orientation, pose_seq_);
  safety_->Step(state_.position_m, state_.orientation, read_ok, model, now_us, &last_);
  if (!device_->Command(last_.force_n, last_.torque_nm)) {
    counters_.command_failures.fetch_add(1, std::memory_order_relaxed);
  }

  // A rejected pose is never published (the server must not solve for it).
  if (!last_.pose_rejected && tick_ % options_.publish_divisor == 0 && poses_ != nullptr) {
    PoseToPublish p;
    p.utime_us = now_us;
    p.seq = pose_seq_;
    for (int k = 0; k < 3; ++k) p.position_m[k] = state_.position_m[k];
    for (int k = 0; k < 4; ++k) p.orientation[k] = state_.orientation[k];
    p.buttons = state_.buttons;
    p.snap_fold_id = snap_ahead_ != nullptr ? snap_ahead_->snap_fold_id() : 0;
    if (poses_->TryPush(p)) ++pose_seq_;
  }
  if (trace_ != nullptr && tick_ % options_.trace_divisor == 0) {
    TraceRow r;
    r.utime_us = now_us;
    r.tick = tick_;
    for (int k = 0; k < 3; ++k) {
      r.position_m[k] = state_.position_m[k];
      r.force_n[k] = last_.force_n[k];
      r.torque_nm[k] = last_.torque_nm[k];
    }
    for (int k = 0; k < 4; ++k) r.orientation[k] = state_.orientation[k];
    r.model_age_ms = last_.model_age_ms;
    r.model_status = last_.model_status;
    r.clamped = last_.clamped;
    r.fading = last_.fading;
    trace_->TryPush(r);
  }
  if (lateness_ != nullptr) {
    const int64_t l = lateness_us < 0 ? 0 : (lateness_us > INT32_MAX ? INT32_MAX : lateness_us);
    lateness_->TryPush(static_cast<int32_t>(l));
  }
  const double* f = last_.force_n;
  counters_.force_norm_n.store(std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]),
                               std::memory_order_relaxed);
  counters_.last_model_receive_us.store(model ? model->receive_us : -1, std::memory_order_relaxed);
  ++tick_;
  counters_.ticks.fetch_add(1, std::memory_order_relaxed);
}

ServoLoop::ServoLoop(ServoTick* tick, ServoLoopOptions options) : tick_(tick), options_(options) {}

ServoLoop::~ServoLoop() { Stop(); }

void ServoLoop::Start(std::string* notes) {
  std::string n;
  if (options_.realtime) {
    // Lock current and future pages: a page fault on the servo thread costs ~ms.
    if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
      n += "servo: mlockall not permitted (" + std::string(std::strerror(errno)) +
           "; raise RLIMIT_MEMLOCK or run as root); pages may fault\n";
    }
  }
  stop_.store(false);
  thread_ = std::thread(&ServoLoop::Run, this);
  // Named, so an operator (top -H) or a test (/proc/PID/task/*/comm) can find it.
  pthread_setname_np(thread_.native_handle(), "servo");
  if (options_.realtime) {
    sched_param sp{};
    sp.sched_priority = options_.fifo_priority;
    const int rc = pthread_setschedparam(thread_.native_handle(), SCHED_FIFO, &sp);
    if (rc == 0) {
      realtime_active_.store(true);
    } else {
      n += "servo: SCHED_FIFO not permitted (run as root or grant CAP_SYS_NICE); "
           "running at normal priority\n";
    }
    // The thread sets its own timer slack first thing; wait briefly for its answer.
    for (int i = 0; i < 200 && timer_slack_ok_.load() < 0; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    if (timer_slack_ok_.load() == 0) {
      n += "servo: PR_SET_TIMERSLACK refused; wake-ups may be up to 50 us late\n";
    }
  }
  if (!n.empty() && n.back() == '\n') n.pop_back();
  if (notes) *notes = n;
}

void ServoLoop::Stop() {
  stop_.store(true);
  if (thread_.joinable()) thread_.join();
}

void ServoLoop::Run() {
  if (options_.realtime) {
    // 1 ns timer slack: the default 50 us slack is 5 % of the period.
    timer_slack_ok_.store(prctl(PR_SET_TIMERSLACK, 1UL, 0, 0, 0) == 0 ? 1 : 0);
  }
  const int64_t period_ns = static_cast<int64_t>(std::llround(1e9 / options_.rate_hz));
  timespec next{};
  clock_gettime(CLOCK_MONOTONIC, &next);
  auto advance = [](timespec* t, int64_t ns) {
    t->tv_nsec += ns;
    while (t->tv_nsec >= 1000000000L) {
      t->tv_nsec -= 1000000000L;
      ++t->tv_sec;
    }
  };
  while (!stop_.load(std::memory_order_relaxed)) {
    advance(&next, period_ns);
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &next, nullptr) == EINTR) {
    }
    const int64_t now_us = realtime::MonotonicMicros();
    const int64_t deadline_us =
        static_cast<int64_t>(next.tv_sec) * 1000000 + next.tv_nsec / 1000;
    const int64_t lateness_us = now_us - deadline_us;
    tick_->Tick(now_us, lateness_us);
    if (lateness_us * 1000 > period_ns) {
      // Missed at least a whole period (a stall): re-anchor instead of firing a burst of
      // catch-up ticks.
      overruns_.fetch_add(1, std::memory_order_relaxed);
      clock_gettime(CLOCK_MONOTONIC, &next);
    }
  }
}

}  // namespace snapthread::device
