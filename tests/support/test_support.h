// The shared test fixtures (tests/support): child processes, temporary directories,
// the tree's paths, unique LCM sessions, waiting for a condition, a virtual X display, a
// loopback TCP connection, the device's trace file.
#pragma once

#include "child_process.h"
#include "device_trace.h"
#include "environment.h"
#include "loopback_socket.h"
#include "session_key_file.h"
#include "temp_dir.h"
#include "virtual_display.h"
