// SIGINT / SIGTERM as a request to stop, the same way in every program: the signals are
// blocked in every thread and taken synchronously (sigtimedwait, or a signalfd), so no
// handler runs at an arbitrary point of any thread and nothing but the caller sees them.
//
//   int main(...) {
//     ...parse the flags...
//     app::StopSignals stop;    // before the first thread: threads inherit the mask
//     ...start the threads...
//     stop.Wait(duration_s);    // or: while (!stop.Requested()) { ...one step... }
#pragma once

#include <signal.h>

namespace snapthread::app {

class StopSignals {
 public:
  // Blocks SIGINT and SIGTERM in the calling thread and in every thread it starts from
  // now on. Construct it in main() before any thread exists (LCM's reader thread, a
  // render thread...): a thread started earlier would still take the default action.
  StopSignals();

  // Waits until a stop signal arrives or `duration_s` has passed (<= 0: no limit).
  // Returns the signal, or 0 when the duration ended first.
  int Wait(double duration_s);

  // Whether a stop signal has arrived (now or at an earlier call); never blocks. For
  // loops that do their own waiting (a render loop, an LCM handle loop).
  bool Requested();

  // The signal that arrived, 0 if none yet.
  int received() const { return received_; }

  // A signalfd (close-on-exec) that becomes readable when a stop signal arrives, for a
  // poll() loop; the caller closes it. -1 (errno set) when it cannot be made.
  int OpenFd() const;

  const sigset_t& signals() const { return signals_; }

 private:
  sigset_t signals_{};
  int received_ = 0;
};

}  // namespace snapthread::app
