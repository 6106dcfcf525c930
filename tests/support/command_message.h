// A command_t as a test sends it (the caller signs it).
#pragma once

#include <cstdint>
#include <string>

#include "snapthread/command_t.hpp"

namespace snapthread::test_support {

inline command_t MakeCommand(int8_t command, const std::string& argument) {
  command_t c{};
  c.utime = 0;
  c.command = command;
  c.argument = argument;
  return c;
}

}  // namespace snapthread::test_support
