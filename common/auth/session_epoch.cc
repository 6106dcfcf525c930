#include "auth/session_epoch.h"

#include <sodium.h>

#include <ctime>

#include "auth/session_key.h"

namespace snapthread::auth {

int64_t NewEpoch() {
  InitSodium();
  int64_t epoch = 0;
  while (epoch == 0) randombytes_buf(&epoch, sizeof epoch);
  return epoch;
}

AuthSequence::AuthSequence() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  last_.store(static_cast<int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec);
}

}  // namespace snapthread::auth
