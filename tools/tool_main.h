// What the offline tools (sweep, stability, bench) share on the command line: the exit
// codes (0 done, 1 failed, 2 bad input, each failure as "<tool>: <why>" on standard
// error) and comma-separated lists.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace snapthread {

struct ToolExitCodes {
  // A SceneError (a scene file that does not load) is bad input (2) rather than a
  // failure (1).
  bool scene_error_is_bad_input = false;
  // std::invalid_argument is bad input (2); false: a failure (1) like any other.
  bool invalid_argument_is_bad_input = true;
};

// Parses argv with `app` (--help exits 0, a bad argument 2) and runs `body`, whose
// return value is the exit code; std::invalid_argument from it exits 2, any other
// exception 1.
int RunTool(const std::string& tool, CLI::App& app, int argc, char** argv, const std::function<int()>& body,
            ToolExitCodes codes = {});

// The non-empty items of a comma-separated list.
std::vector<std::string> SplitList(const std::string& text);

// Each item of a comma-separated list through `parse`; the first item it refuses throws
// std::invalid_argument("<option>: '<item>' <refusal>").
template <typename T>
std::vector<T> ParseList(const std::string& text, const std::string& option, const std::string& refusal,
                         const std::function<bool(const std::string&, T*)>& parse) {
  std::vector<T> values;
  for (const auto& item : SplitList(text)) {
    T value{};
    if (!parse(item, &value)) throw std::invalid_argument(option + ": '" + item + "' " + refusal);
    values.push_back(value);
  }
  return values;
}

// The whole text as a number (false for trailing characters, no digits or overflow).
bool ParseWhole(const std::string& text, int* value);
bool ParseWhole(const std::string& text, double* value);

}  // namespace snapthread
