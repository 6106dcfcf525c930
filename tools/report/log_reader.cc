#include "log_reader.h"

#include <cstdio>
#include <filesystem>
#include <memory>

namespace snapthread::report {
namespace {

constexpr uint32_t kSyncWord = 0xEDA1DA01;  // LCM log event marker (big-endian on disk)
constexpr int64_t kEventHeaderBytes = 4 + 8 + 8 + 4 + 4;  // sync, eventnum, time, lengths

// Offset of the next sync word at or after `from`, or -1.
int64_t FindSync(const std::string& path, int64_t from) {
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f || std::fseek(f.get(), long(from), SEEK_SET) != 0) return -1;
  uint32_t window = 0;
  int64_t pos = from;
  int c;
  while ((c = std::fgetc(f.get())) != EOF) {
    window = (window << 8) | uint32_t(c);
    ++pos;
    if (pos - from >= 4 && window == kSyncWord) return pos - 4;
  }
  return -1;
}

}  // namespace

bool ReadLog(const std::string& path, const std::function<void(const lcm::LogEvent&)>& on_event,
             LogReadStats* stats, std::string* error) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) {
    *error = "cannot read " + path + ": " + ec.message();
    return false;
  }
  stats->file_bytes = int64_t(size);
  lcm::LogFile log(path, "r");
  if (!log.good()) {
    *error = "cannot open " + path + " as an LCM log";
    return false;
  }
  FILE* fp = log.getFilePtr();  // position queries only; LogFile does the reading
  int64_t good_end = 0;         // end of the last intact event
  while (true) {
    const lcm::LogEvent* e = log.readNextEvent();
    const int64_t pos = std::ftell(fp);
    if (e != nullptr) {
      const int64_t expected = kEventHeaderBytes + int64_t(e->channel.size()) + e->datalen;
      const int64_t start = pos - expected;
      if (start > good_end) {  // LogFile skipped garbage to the next sync word
        stats->skipped_bytes += start - good_end;
        stats->resyncs++;
        stats->warnings.push_back("skipped " + std::to_string(start - good_end) +
                                  " damaged bytes at offset " + std::to_string(good_end));
      }
      good_end = pos;
      stats->events++;
      on_event(*e);
      continue;
    }
    if (good_end >= stats->file_bytes) break;  // clean end of file
    // LogFile gave up inside the file: find the next event after the damaged one.
    const int64_t next = FindSync(path, good_end + 1);
    if (next < 0) {
      stats->skipped_bytes += stats->file_bytes - good_end;
      stats->truncated_tail = true;
      stats->warnings.push_back("log ends inside an event: " +
                                std::to_string(stats->file_bytes - good_end) +
                                " trailing bytes after offset " + std::to_string(good_end) +
                                " could not be read (truncated log?)");
      break;
    }
    stats->skipped_bytes += next - good_end;
    stats->resyncs++;
    stats->warnings.push_back("damaged event at offset " + std::to_string(good_end) +
                              ", resumed at " + std::to_string(next));
    if (std::fseek(fp, long(next), SEEK_SET) != 0) break;
    good_end = next;
  }
  return true;
}

}  // namespace snapthread::report
