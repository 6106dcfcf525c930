// Clocks used in messages: device poses carry CLOCK_MONOTONIC (the device measures
// round trips on its own clock), server messages CLOCK_REALTIME.
#pragma once

#include <cstdint>

namespace snapthread::realtime {

// CLOCK_MONOTONIC in microseconds. Async-signal-safe and allocation-free.
int64_t MonotonicMicros();
// CLOCK_REALTIME in microseconds.
int64_t RealtimeMicros();

}  // namespace snapthread::realtime
