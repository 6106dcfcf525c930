#include "observer_token.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <sodium.h>

#include <cstdio>
#include <stdexcept>

#include "auth/session_key.h"

namespace snapthread::web {

std::string GenerateObserverToken() {
  auth::InitSodium();
  unsigned char bytes[16];
  randombytes_buf(bytes, sizeof bytes);
  char hex[2 * sizeof bytes + 1];
  sodium_bin2hex(hex, sizeof hex, bytes, sizeof bytes);
  return hex;
}

std::string_view TargetPath(std::string_view target) {
  return target.substr(0, target.find('?'));
}

std::string QueryParameter(std::string_view target, std::string_view name) {
  const size_t q = target.find('?');
  if (q == std::string_view::npos) return "";
  std::string_view query = target.substr(q + 1);
  while (!query.empty()) {
    const size_t amp = query.find('&');
    const std::string_view pair = query.substr(0, amp);
    const size_t eq = pair.find('=');
    if (pair.substr(0, eq) == name) return eq == std::string_view::npos ? "" : std::string(pair.substr(eq + 1));
    if (amp == std::string_view::npos) break;
    query.remove_prefix(amp + 1);
  }
  return "";
}

bool TokenMatches(std::string_view given, std::string_view expected) {
  if (expected.empty()) return false;
  auth::InitSodium();
  unsigned char a[crypto_generichash_BYTES], b[crypto_generichash_BYTES];
  static_assert(crypto_generichash_BYTES == 32);
  crypto_generichash(a, sizeof a, reinterpret_cast<const unsigned char*>(given.data()), given.size(), nullptr, 0);
  crypto_generichash(b, sizeof b, reinterpret_cast<const unsigned char*>(expected.data()), expected.size(),
                     nullptr, 0);
  return crypto_verify_32(a, b) == 0;
}

std::string TokenProblem(std::string_view token) {
  if (token.size() < 16 || token.size() > 128) {
    return "an observer token has 16 to 128 characters (this one " + std::to_string(token.size()) + ")";
  }
  for (const char c : token) {
    const bool ok = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') ||
                    c == '.' || c == '_' || c == '~' || c == '-';
    if (!ok) return "an observer token has only the characters A-Z a-z 0-9 . _ ~ -";
  }
  return "";
}

std::string LoadTokenFile(const std::string& path) {
  // O_NONBLOCK: a FIFO named by mistake must not hang the start.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) throw std::runtime_error("--token-file " + path + ": cannot open it");
  struct stat st {};
  std::string text;
  std::string problem;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    problem = "not a regular file";
  } else if ((st.st_mode & 077) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%04o", static_cast<unsigned>(st.st_mode & 07777));
    problem = std::string("has mode ") + mode + ": group or others may read or write it. Fix: chmod 600 " + path;
  } else if (st.st_size > 4096) {
    problem = "longer than a token";
  } else {
    char buffer[4096];
    ssize_t n;
    while ((n = ::read(fd, buffer, sizeof buffer)) > 0) text.append(buffer, static_cast<size_t>(n));
  }
  ::close(fd);
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  if (problem.empty()) problem = TokenProblem(text);
  if (!problem.empty()) throw std::runtime_error("--token-file " + path + ": " + problem);
  return text;
}

}  // namespace snapthread::web
