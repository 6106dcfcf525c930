#include "log_reader.h"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <vector>

namespace snapthread::report {
namespace {

constexpr uint32_t kSyncWord = 0xEDA1DA01;  // LCM log event marker (big-endian on disk)
constexpr int64_t kEventHeaderBytes = 4 + 8 + 8 + 4 + 4;  // sync, eventnum, time, lengths

// Offset of the next sync word at or after `from`, or -1. Buffered: a log with a
// hundred megabytes of garbage is searched in well under a second.
int64_t FindSync(const std::string& path, int64_t from) {
  std::unique_ptr<FILE, int (*)(FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f || std::fseek(f.get(), long(from), SEEK_SET) != 0) return -1;
  static constexpr unsigned char kSync[4] = {0xED, 0xA1, 0xDA, 0x01};  // big-endian
  std::vector<unsigned char> buf(1 << 16);
  size_t keep = 0;      // bytes carried over from the previous chunk (a split sync word)
  int64_t base = from;  // file offset of buf[0]
  while (true) {
    const size_t got = std::fread(buf.data() + keep, 1, buf.size() - keep, f.get());
    if (got == 0) return -1;
    const size_t n = keep + got;
    for (size_t i = 0; i + 4 <= n; ++i) {
      if (buf[i] == kSync[0] && std::memcmp(&buf[i], kSync, 4) == 0) return base + int64_t(i);
    }
    keep = std::min<size_t>(3, n);
    std::memmove(buf.data(), buf.data() + n - keep, keep);
    base += int64_t(n - keep);
  }
}

// Whether the next 4 bytes of fp are a sync word (fp's position is kept).
bool AtSyncWord(FILE* fp) {
  const long here = std::ftell(fp);
  unsigned char b[4] = {0, 0, 0, 0};
  const size_t got = std::fread(b, 1, 4, fp);
  std::fseek(fp, here, SEEK_SET);
  const uint32_t word = uint32_t(b[0]) << 24 | uint32_t(b[1]) << 16 | uint32_t(b[2]) << 8 | b[3];
  return got == 4 && word == kSyncWord;
}

}  // namespace

bool ReadLog(const std::string& path, const std::function<void(const lcm::LogEvent&)>& on_event,
             LogReadStats* stats, std::string* error) {
  std::error_code ec;
  // A FIFO or a device would block fopen or never end: only a regular file is a log.
  const auto kind = std::filesystem::status(path, ec).type();
  if (!ec && kind != std::filesystem::file_type::regular) {
    *error = "cannot read " + path + ": " +
             (kind == std::filesystem::file_type::directory ? "a directory" : "not a regular file") +
             " (expected an LCM log written by lcm-logger)";
    return false;
  }
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
  FILE* fp = log.getFilePtr();  // positions and a 4-byte peek; LogFile reads the events
  int64_t good_end = 0;         // end of the last intact event
  const auto truncated_tail = [&] {
    stats->skipped_bytes += stats->file_bytes - good_end;
    stats->truncated_tail = true;
    stats->warnings.push_back("log ends inside an event: " +
                              std::to_string(stats->file_bytes - good_end) +
                              " trailing bytes after offset " + std::to_string(good_end) +
                              " could not be read (truncated log?)");
  };
  while (true) {
    // lcm::LogFile skips damaged bytes one fgetc at a time (seconds for 100 MB of
    // garbage): find the next sync word here instead, and let LogFile start there.
    const int64_t here = std::ftell(fp);
    if (here < stats->file_bytes && !AtSyncWord(fp)) {
      const int64_t next = FindSync(path, here);
      if (next < 0) {
        truncated_tail();
        break;
      }
      if (std::fseek(fp, long(next), SEEK_SET) != 0) break;
    }
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
      truncated_tail();
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
