// Files a user names on a command line (a scene, a path CSV): read whole, bounded, and
// never blocking. A wrong name must end in a message, not a hang: a FIFO would block
// open() until a writer comes, /dev/zero never ends, a 100 MB file would be parsed for
// minutes. So the file is opened with O_NONBLOCK, the opened descriptor is checked
// (fstat: a regular file, at most max_bytes), and the read stops at max_bytes.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

namespace snapthread {

class InputFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "a directory", "a FIFO", "a character device", ... for a stat mode that is not a
// regular file ("a regular file" for one).
const char* FileKindName(unsigned int st_mode);

// The whole text of `path`. Throws InputFileError("<path>: <why>") when it cannot be
// opened, is not a regular file (directory, FIFO, device, socket) or holds more than
// max_bytes; `what` names the file's role in the message ("scene file", "path CSV").
std::string ReadInputFile(const std::string& path, std::size_t max_bytes, const std::string& what);

}  // namespace snapthread
