// SIGINT / SIGTERM end the viewer cleanly (issue 12 item 5): the handler only sets a
// flag; the frame and print-rates loops check it and return with exit status 0.
#pragma once

namespace snapthread::viewer {

// Installs the handlers (once, at start-up).
void InstallStopSignals();
// A stop signal has arrived.
bool StopRequested();

}  // namespace snapthread::viewer
