#include "session_key_file.h"

#include <cstdlib>

#include "auth/key_file.h"

namespace snapthread::test_support {
namespace {

auth::SessionKey WriteKey(const std::string& path) {
  const auth::KeyLocation where{path, "test"};
  auth::WriteNewKey(where, /*overwrite=*/false);
  return auth::LoadKey(where);
}

}  // namespace

SessionKeyFile::SessionKeyFile()
    : path_(dir_.path() + "/session.key"), key_(WriteKey(path_)) {
  if (const char* previous = std::getenv(auth::kKeyFileEnv)) {
    had_previous_ = true;
    previous_ = previous;
  }
  ::setenv(auth::kKeyFileEnv, path_.c_str(), 1);
}

SessionKeyFile::~SessionKeyFile() {
  if (had_previous_) {
    ::setenv(auth::kKeyFileEnv, previous_.c_str(), 1);
  } else {
    ::unsetenv(auth::kKeyFileEnv);
  }
}

}  // namespace snapthread::test_support
