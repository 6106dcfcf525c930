// SIGHUP as a request to reload the credential (snapthread-device): blocked in every
// thread and taken synchronously by the main thread, like app::StopSignals, so it never
// stops the program and no handler runs on the servo thread.
//
//   ReloadSignal reload;   // in main() before any thread, next to app::StopSignals
//   ...
//   if (reload.Take()) { ...reload... }   // never blocks
#pragma once

#include <signal.h>

namespace snapthread::device {

class ReloadSignal {
 public:
  // Blocks SIGHUP in the calling thread and in every thread it starts from now on.
  ReloadSignal();
  // Whether SIGHUP arrived since the last call (several count as one); never blocks.
  bool Take();

 private:
  sigset_t signals_{};
};

}  // namespace snapthread::device
