#include "tool_main.h"

#include <iostream>
#include <sstream>

#include "scene/scene.h"

namespace snapthread {

int RunTool(const std::string& tool, CLI::App& app, int argc, char** argv, const std::function<int()>& body,
            ToolExitCodes codes) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  try {
    return body();
  } catch (const SceneError& e) {
    std::cerr << tool << ": " << e.what() << '\n';
    return codes.scene_error_is_bad_input ? 2 : 1;
  } catch (const std::invalid_argument& e) {
    std::cerr << tool << ": " << e.what() << '\n';
    return codes.invalid_argument_is_bad_input ? 2 : 1;
  } catch (const std::exception& e) {
    std::cerr << tool << ": " << e.what() << '\n';
    return 1;
  }
}

std::vector<std::string> SplitList(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) items.push_back(item);
  return items;
}

namespace {
template <typename T, typename Convert>
bool ParseWholeWith(const std::string& text, T* value, Convert convert) {
  size_t used = 0;
  try {
    *value = convert(text, &used);
  } catch (const std::exception&) {
    return false;
  }
  return used == text.size();
}
}  // namespace

bool ParseWhole(const std::string& text, int* value) {
  return ParseWholeWith(text, value, [](const std::string& s, size_t* used) { return std::stoi(s, used); });
}

bool ParseWhole(const std::string& text, double* value) {
  return ParseWholeWith(text, value, [](const std::string& s, size_t* used) { return std::stod(s, used); });
}

}  // namespace snapthread
