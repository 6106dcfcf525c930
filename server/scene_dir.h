// Scenes named by a LOAD_SCENE command. A command comes from the
// network, so it names a scene, never a path: only a regular file of at most
// kMaxSceneFileBytes directly inside the scene directory is ever opened. Everything
// else (a path, "..", a symlink, a device, a FIFO, a directory, a big file) is refused
// with a SceneNameError that says what was wrong.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

#include "scene/scene.h"

namespace snapthread::server {

// The same 1 MiB limit as a scene named on a command line (scene/scene.h).
using snapthread::kMaxSceneFileBytes;

// The argument of LOAD_SCENE is not an acceptable scene name or file (a policy refusal,
// counted in rejected_messages; a scene that opens but does not parse is a SceneError).
class SceneNameError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The scene directory built into the binary (the project's scenes/).
std::string DefaultSceneDir();

// "curve2d_snap" or "curve2d_snap.yaml" -> "curve2d_snap.yaml". Throws SceneNameError
// for an empty name, a path separator, "..", a leading '.', or a character outside
// [A-Za-z0-9_.-].
std::string SceneFileName(const std::string& name);

// The text of the scene `name` in `dir`, and its path in *path. Never blocks on the file
// (O_NONBLOCK), never follows a symlink (realpath check + O_NOFOLLOW), and checks the
// opened descriptor (fstat), not the name, so a swap after the check changes nothing.
std::string ReadSceneByName(const std::string& dir, const std::string& name, std::string* path);

}  // namespace snapthread::server
