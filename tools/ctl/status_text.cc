#include "status_text.h"

#include <cstdio>

#include "messages/channels.h"
#include "snapthread/force_model_t.hpp"

namespace snapthread::ctl {

std::string TerminalText(std::string_view text, size_t max_bytes) {
  std::string out;
  const size_t shown = text.size() < max_bytes ? text.size() : max_bytes;
  for (size_t i = 0; i < shown; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 0x20 && c < 0x7f && c != '\\') {
      out += static_cast<char>(c);
    } else {
      out += messages::EscapeForDisplay(text.substr(i, 1));
    }
  }
  if (shown < text.size()) out += "...[" + std::to_string(text.size()) + " bytes]";
  return out;
}

std::string StatusName(int8_t status) {
  switch (status) {
    case force_model_t::STATUS_REGULAR: return "regular";
    case force_model_t::STATUS_NEAR_FOLD: return "near fold";
    case force_model_t::STATUS_SNAPPED: return "snapped";
    case force_model_t::STATUS_INVALID: return "invalid";
    case force_model_t::STATUS_SNAPPING: return "snapping";
    default: return "status " + std::to_string(status);
  }
}

std::string StatusText(const solver_status_t& s) {
  using messages::EscapeForDisplay;
  char numbers[512];
  std::snprintf(numbers, sizeof numbers,
                "update rate: %.1f Hz\n"
                "solve p50/p99: %.0f / %.0f us\n"
                "updates: %lld\n"
                "snaps: %lld\n"
                "dropped poses: %lld\n"
                "rejected messages: %lld\n",
                s.update_rate_hz, s.solve_us_p50, s.solve_us_p99,
                static_cast<long long>(s.updates), static_cast<long long>(s.snaps),
                static_cast<long long>(s.dropped_poses),
                static_cast<long long>(s.rejected_messages));
  std::string knot = s.knot.empty() ? std::string("not computed") : EscapeForDisplay(s.knot);
  if (s.knot_determinant > 0) knot += " (determinant " + std::to_string(s.knot_determinant) + ")";
  return "scene: " + EscapeForDisplay(s.scene) + "\n" +
         "method: " + EscapeForDisplay(s.method) + "\n" +
         "status: " + StatusName(s.status) + "\n" + numbers +
         "knot: " + knot + "\n" +
         "contacts: " + std::to_string(s.contacts) + "\n" +
         "refusals: " + (s.refusals.empty() ? std::string("none") : EscapeForDisplay(s.refusals)) + "\n";
}

}  // namespace snapthread::ctl
