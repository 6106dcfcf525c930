// The snapthread-viewer process: window + render loop (or the --print-rates observer).
#pragma once

#include "app/exit_codes.h"
#include "app/stop_signals.h"
#include "viewer_options.h"

namespace snapthread::viewer {

// Exit codes of the process (app/exit_codes.h: the viewer keeps its documented 2).
inline constexpr int kExitOk = app::kExitOk;
inline constexpr int kExitSetupFailed = app::kExitFailure;  // LCM, key, window or GL context
inline constexpr int kExitBadArguments = app::kExitUsage;
inline constexpr int kExitTimeout = app::kExitTimeout;  // screenshot: not enough shapes before --timeout-s

// Opens the window and runs until closed, --duration-s, a stop signal, or the screenshot
// is written.
int RunViewer(const ViewerOptions& options, app::StopSignals* stop);
// Prints the rates of every <session>_* channel once per second (no window) until
// --duration-s or a stop signal.
int RunPrintRates(const ViewerOptions& options, app::StopSignals* stop);

}  // namespace snapthread::viewer
