// Parsing a program's command line with CLI11 the same way in every program: --help
// exits 0, a bad argument prints CLI11's message (it names the flag) and exits with the
// program's usage code, and "nan" is refused where a number must be finite.
#pragma once

#include <optional>
#include <string_view>

#include <CLI/CLI.hpp>

namespace snapthread::app {

// Parses argv with `app`. nullopt: go on; otherwise the exit code to return from main():
// kExitOk after --help, `usage_exit` after a bad argument (the message is printed).
std::optional<int> ParseCommandLine(CLI::App& app, int argc, char** argv, int usage_exit);

// A validator for numeric options that refuses NaN and infinities. CLI11's range checks
// let "nan" through (every comparison with NaN is false): add it after them.
CLI::Validator FiniteNumber();

// Prints "<program>: <message>" on standard error and returns `exit_code`, for the
// `return Fail(...)` lines of a main().
int Fail(std::string_view program, int exit_code, std::string_view message);

}  // namespace snapthread::app
