// The exit codes of snapthread's programs, in one table.
//
// Every program exits kExitOk after a clean stop (SIGINT / SIGTERM, its --duration, or
// its work done), kExitFailure when something outside its arguments failed (LCM did not
// start, a file could not be written, no window), and kExitUsage for bad arguments, each
// with one line "<program>: <why>" on standard error that names the flag.
//
// A program that waits for something with a deadline exits kExitTimeout when it passed:
// snapthread-ctl without an authenticated reply, the viewer's screenshot without its
// shapes (docs/cli.md).
#pragma once

namespace snapthread::app {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitUsage = 2;
// A deadline passed: a peer's answer (snapthread-ctl) or the shapes of a screenshot
// (snapthread-viewer) did not arrive in time.
inline constexpr int kExitTimeout = 3;
inline constexpr int kExitNoReply = kExitTimeout;

}  // namespace snapthread::app
