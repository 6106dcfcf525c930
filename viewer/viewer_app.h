// The snapthread-viewer process: window + render loop (or the --print-rates observer).
#pragma once

#include "viewer_options.h"

namespace snapthread::viewer {

// Exit codes of the process.
inline constexpr int kExitOk = 0;
inline constexpr int kExitSetupFailed = 1;  // LCM, window or GL context could not be created
inline constexpr int kExitTimeout = 2;      // screenshot: not enough shapes before --timeout-s

// Opens the window and runs until closed, --duration-s, or the screenshot is written.
int RunViewer(const ViewerOptions& options);
// Prints the rates of every <session>_* channel once per second (no window).
int RunPrintRates(const ViewerOptions& options);

}  // namespace snapthread::viewer
