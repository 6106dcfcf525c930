// The shared test fixtures (tests/support): child processes, temporary directories,
// the tree's paths, unique LCM sessions, waiting for a condition.
#pragma once

#include "child_process.h"
#include "environment.h"
#include "temp_dir.h"
