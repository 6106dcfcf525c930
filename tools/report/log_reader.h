// Reads an LCM log (lcm::LogFile) event by event and says how much of it could be read.
// lcm::LogFile stops at the first damaged event; this reader notices where it stopped
// (file position against file size), searches the next event's sync word and carries on,
// so a log with a corrupt middle or a truncated tail still yields every intact event.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

namespace snapthread::report {

struct LogReadStats {
  int64_t file_bytes = 0;
  int64_t events = 0;            // intact events delivered
  int64_t skipped_bytes = 0;     // bytes that belonged to no intact event
  int resyncs = 0;               // times reading resumed after damage
  bool truncated_tail = false;   // the file ends inside an event
  std::vector<std::string> warnings;
  bool Partial() const { return skipped_bytes > 0 || truncated_tail; }
};

// Calls on_event for every intact event in file order. False (reason in *error) only when
// the file cannot be opened as a log at all.
bool ReadLog(const std::string& path, const std::function<void(const lcm::LogEvent&)>& on_event,
             LogReadStats* stats, std::string* error);

}  // namespace snapthread::report
