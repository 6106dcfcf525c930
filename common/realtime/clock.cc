#include "realtime/clock.h"

#include <time.h>

namespace snapthread::realtime {
namespace {
int64_t Micros(clockid_t id) {
  timespec ts{};
  clock_gettime(id, &ts);
  return static_cast<int64_t>(ts.tv_sec) * 1000000 + ts.tv_nsec / 1000;
}
}  // namespace

int64_t MonotonicMicros() { return Micros(CLOCK_MONOTONIC); }
int64_t RealtimeMicros() { return Micros(CLOCK_REALTIME); }

}  // namespace snapthread::realtime
