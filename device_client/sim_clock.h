// Time source of the simulated backends: CLOCK_MONOTONIC by default, replaceable in
// tests by any allocation-free function returning microseconds.
#pragma once

#include <cstdint>

namespace snapthread::device {

using MicrosClock = int64_t (*)();

}  // namespace snapthread::device
