// The exit codes of snapthread's programs, in one table.
//
// Every program exits kExitOk after a clean stop (SIGINT / SIGTERM, its --duration, or
// its work done), kExitFailure when something outside its arguments failed (LCM did not
// start, a file could not be written, no window), and kExitUsage for bad arguments, each
// with one line "<program>: <why>" on standard error that names the flag.
//
// Older programs documented a different use of 1 and 2 before this table existed, and
// scripts rely on them, so they keep it (each program's header says which):
// snapthread-viewer exits 2 when a screenshot's shapes did not arrive in time and 1 for
// bad arguments; snapthread-report exits 2 when nothing of the log could be read and 1
// for bad arguments; snapthread-web and snapthread-logger exit 1 for every failure.
// kExitUsageAsFailure names that "bad arguments are 1" choice where such a program
// passes its usage code.
#pragma once

namespace snapthread::app {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitUsage = 2;
// A program that waits for a peer's answer (snapthread-ctl) and got none in time.
inline constexpr int kExitNoReply = 3;
// For the programs above whose bad arguments exit 1.
inline constexpr int kExitUsageAsFailure = kExitFailure;

}  // namespace snapthread::app
