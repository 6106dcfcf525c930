// The end-of-run summary of the server's statistics (Stats()): SummaryJson's figures and
// the final log line.
#include <cstdio>
#include <string>
#include <vector>

#include "server.h"

namespace snapthread::server {

namespace {

// One figure of the end-of-run summary; counts print as integers.
struct Figure {
  const char* key;
  double value;
  bool count;
  bool in_final_line;  // also on the final log line
};

std::vector<Figure> Figures(const ServerStats& s) {
  auto n = [](int64_t v) { return static_cast<double>(v); };
  std::vector<Figure> figures = {{"updates", n(s.updates), true, true},
          {"update_rate_hz", s.update_rate_hz, false, true},
          {"solve_us_p50", s.solve_us_p50, false, true},
          {"solve_us_p99", s.solve_us_p99, false, true},
          {"snaps", n(s.snaps), true, true},
          {"dropped_poses", n(s.dropped_poses), true, true},
          {"rejected_messages", n(s.rejected_messages), true, true},
          {"poses_received", n(s.poses_received), true, false},
          {"invalid_models", n(s.invalid_models), true, true},
          {"commands_applied", n(s.commands_applied), true, false},
          {"commands_refused", n(s.commands_refused), true, false},
          {"shapes_published", n(s.shapes_published), true, false},
          {"statuses_published", n(s.statuses_published), true, false},
          {"publish_failures", n(s.publish_failures), true, false}};
  if (s.checkpoints) {  // --state-dir only: the summary without it is unchanged
    figures.insert(figures.end(),
                   {{"resumed", n(s.resumed ? 1 : 0), true, false},
                    {"checkpoints_written", n(s.checkpoint.written), true, false},
                    {"checkpoint_failures", n(s.checkpoint.failed), true, false},
                    {"checkpoint_write_us_p50", s.checkpoint.write_us_p50, false, false},
                    {"checkpoint_write_us_p99", s.checkpoint.write_us_p99, false, false},
                    {"checkpoint_write_us_max", s.checkpoint.write_us_max, false, false},
                    {"checkpoint_offer_us_p50", s.checkpoint_offer_us_p50, false, false},
                    {"checkpoint_offer_us_p99", s.checkpoint_offer_us_p99, false, false}});
  }
  return figures;
}

std::string FigureText(const Figure& f, int decimals) {
  char buf[64];
  if (f.count)
    std::snprintf(buf, sizeof(buf), "%lld", static_cast<long long>(f.value));
  else
    std::snprintf(buf, sizeof(buf), "%.*f", decimals, f.value);
  return buf;
}

}  // namespace

std::string Server::SummaryJson() const {
  std::string json = "{\n";
  const std::vector<Figure> figures = Figures(Stats());
  for (size_t i = 0; i < figures.size(); ++i) {
    json += std::string("  \"") + figures[i].key + "\": " + FigureText(figures[i], 3);
    json += i + 1 < figures.size() ? ",\n" : "\n";
  }
  return json + "}\n";
}

std::string Server::FinalReport() const {
  std::string line = "final:";
  for (const Figure& f : Figures(Stats()))
    if (f.in_final_line) line += std::string(" ") + f.key + "=" + FigureText(f, 1);
  return line;
}

}  // namespace snapthread::server
