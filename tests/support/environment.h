// Where a test finds the tree and the binaries, unique LCM session names on the shared
// loopback multicast group, files read whole, and waiting for a condition.
#pragma once

#include <functional>
#include <map>
#include <string>

namespace snapthread::test_support {

// The LCM URL of the process tests: multicast on loopback only (ttl=0).
inline constexpr char kLoopbackLcmUrl[] = "udpm://239.255.76.67:7667?ttl=0";

std::string SourceDir();  // $SNAPTHREAD_SOURCE_DIR, else the configured source tree
std::string BinDir();     // $SNAPTHREAD_BIN_DIR, else the configured build's bin/
std::string ScenePath(const std::string& file);  // SourceDir()/scenes/file

// "<prefix>_<pid>_<counter>_<random>": unique per process, call and run, because
// parallel ctest jobs share the multicast group. Keep the prefix short (LCM channel names
// are at most 63 bytes with the channel suffix).
std::string UniqueSession(const std::string& prefix);

// $SNAPTHREAD_SPEED_SCALE (default 1, at least 1): how many times slower than the Release
// build this build runs; deploy/test.sh sets it for the sanitizer run (16: the rod's
// sweep takes 14x the CPU time under ASan + UBSan). Only thresholds that are about speed
// are scaled by it (a time budget, a start-up-and-refusal time, models per servo tick,
// shapes and frames per second), never a safety property (|F| limits, finiteness, ordering,
// rejection counts, the servo's own tick rate).
double SpeedScale();

// The whole file ("" when it cannot be read).
std::string ReadFile(const std::string& path);
// The numbers of a flat JSON object ({"key": number, ...}) in a file, e.g. a --summary.
std::map<std::string, double> ReadJsonNumbers(const std::string& path);

// Polls `condition` every poll_s until it holds (true) or timeout_s has passed (false;
// the condition is asked once more at the deadline).
bool WaitUntil(const std::function<bool()>& condition, double timeout_s, double poll_s = 0.01);
// Waits until `path` exists and is not empty.
bool WaitForFile(const std::string& path, double timeout_s);

}  // namespace snapthread::test_support
