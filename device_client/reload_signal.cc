#include "reload_signal.h"

#include <pthread.h>

#include <ctime>

namespace snapthread::device {

ReloadSignal::ReloadSignal() {
  sigemptyset(&signals_);
  sigaddset(&signals_, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals_, nullptr);
}

bool ReloadSignal::Take() {
  const timespec now{};
  bool taken = false;
  while (sigtimedwait(&signals_, nullptr, &now) == SIGHUP) taken = true;
  return taken;
}

}  // namespace snapthread::device
