#include "app/command_line.h"

#include <cmath>
#include <cstdio>
#include <string>

#include "app/exit_codes.h"

namespace snapthread::app {

std::optional<int> ParseCommandLine(CLI::App& app, int argc, char** argv, int usage_exit) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // app.exit prints the help (code 0) or CLI11's message naming the flag.
    return app.exit(e) == 0 ? kExitOk : usage_exit;
  }
  return std::nullopt;
}

CLI::Validator FiniteNumber() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double value = 0.0;
        if (!CLI::detail::lexical_cast(text, value)) return "expected a number, got " + text;
        return std::isfinite(value) ? std::string() : "expected a finite number, got " + text;
      },
      "FINITE");
}

int Fail(std::string_view program, int exit_code, std::string_view message) {
  std::fprintf(stderr, "%.*s: %.*s\n", static_cast<int>(program.size()), program.data(),
               static_cast<int>(message.size()), message.data());
  return exit_code;
}

}  // namespace snapthread::app
