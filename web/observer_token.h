// The observer token: who may open the page when the bridge listens beyond loopback.
// Bound to 127.0.0.1 (or any loopback address) only this machine's users reach the page,
// as they reach the session's LCM traffic; on another interface every request, the page's
// files and its WebSocket alike, must carry the token (?token=, or the cookie the bridge
// sets from it: access_policy.h) or gets 401.
#pragma once

#include <string>
#include <string_view>

namespace snapthread::web {

// 32 hex digits from libsodium's random source (128 bits).
std::string GenerateObserverToken();

// The value of `name` in the query of a request target ("/ws?token=ab&x=1"), undecoded;
// "" when absent.
std::string QueryParameter(std::string_view target, std::string_view name);

// The path of a request target, without the query.
std::string_view TargetPath(std::string_view target);

// Constant-time comparison: both are hashed (BLAKE2b-256) and the hashes compared with
// crypto_verify_32, so the time of a refusal says nothing about how much of a guess was
// right, nor about the token's length. An empty `expected` never matches.
bool TokenMatches(std::string_view given, std::string_view expected);

// "" when `token` may be an observer token, else what is wrong with it: 16 to 128
// characters of A-Z a-z 0-9 . _ ~ - (they go into a URL and a cookie unencoded).
std::string TokenProblem(std::string_view token);

// The token in `path` (--token-file): the file's text without the trailing newline. Throws
// std::runtime_error naming the file and the fix when it is not a regular file, may be
// read or written by group or others, or holds no valid token (TokenProblem).
std::string LoadTokenFile(const std::string& path);

}  // namespace snapthread::web
