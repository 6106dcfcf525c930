// The observer token: who may open the page when the bridge listens beyond loopback.
// Bound to 127.0.0.1 (or any loopback address) only this machine's users reach the page,
// as they reach the session's LCM traffic; on another interface every request, the page's
// files and its WebSocket alike, must carry ?token=<token> or gets 401.
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

// Constant-time comparison (sodium_memcmp), so the time of a refusal says nothing about
// how much of a guess was right. An empty `expected` never matches.
bool TokenMatches(std::string_view given, std::string_view expected);

}  // namespace snapthread::web
