// Issue 12 item 6: bad input to every binary ends within 2 s with a non-zero exit and a
// message naming the field or the reason; no signal, no hang. One row per case: the
// binary, its arguments, what the input file is, and the text its stderr must hold.
#pragma once

#include <string>
#include <vector>

namespace snapthread::bad_input {

// What "{in}" in a case's arguments is. Text inputs are written to <case dir>/in.yaml.
enum class InputKind {
  kNone,        // no {in}
  kText,        // a file holding `text`
  kFifo,        // a FIFO nobody writes to (open() would block without O_NONBLOCK)
  kDirectory,   // a directory
  kHuge,        // a sparse 100 MB file of zeros
  kDevZero,     // /dev/zero (endless)
  kMissing,     // a path that does not exist
  kSceneDir,      // a copy of scenes/ whose `file` holds `text`
  kSceneDirFifo,  // a copy of scenes/ whose `file` is a FIFO
  kKeyMode0644, // a 32-byte key file readable by everyone
  kKeyShort,    // a 5-byte key file of mode 0600
};

struct Input {
  InputKind kind = InputKind::kNone;
  std::string text;  // kText, kSceneDir
  std::string file;  // kSceneDir, kSceneDirFifo: which scene file is replaced
};

struct Case {
  std::string binary;             // in build/bin, or "deploy/..." in the source tree
  std::vector<std::string> args;  // "{in}": the input; "{dir}": the case's own directory
  Input input;
  std::string expect;             // must appear in stderr + stdout
};

// The rows, by binary (bad_input_cases.cc).
std::vector<Case> SceneFileCases();  // every scene-reading binary x every bad scene
std::vector<Case> CommandLineCases();

}  // namespace snapthread::bad_input
