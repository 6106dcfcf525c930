// Parameters of one snapthread-viewer process (set from the command line).
#pragma once

#include <string>

#include "app/common_flags.h"

namespace snapthread::viewer {

struct ViewerOptions {
  app::CommonFlags common;  // --session (env SNAPTHREAD_SESSION), --lcm-url, --key
  std::string lcm_url;      // the URL opened: app::LcmUrl(common), with a receiver's buffer
  int width = 1280;   // window size, pixels
  int height = 720;
  std::string screenshot_path;  // non-empty: headless screenshot mode
  int after_shapes = 1;         // screenshot after this many valid shapes
  double timeout_s = 10.0;      // screenshot / print-rates: give up after this long (0 = never)
  bool print_rates = false;     // print live channel rates once per second, no window
  double duration_s = 0.0;      // exit after this long (0 = run until closed)
  double max_fps = 60.0;        // render at most this often (the machine may be shared)
  bool grasp_mode = false;      // mouse drag of the grasp publishes device_state_t
  std::string scene_path;       // needed by grasp mode (device mapping)
};

}  // namespace snapthread::viewer
