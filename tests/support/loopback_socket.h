// A TCP connection to a server on this machine (127.0.0.1), for the tests that speak raw
// HTTP or WebSocket to snapthread-web, choosing every header themselves.
#pragma once

namespace snapthread::test_support {

// A connected socket to 127.0.0.1:port whose reads time out after receive_timeout_s (so a
// silent server fails the test instead of hanging it), or -1. The caller closes it.
int ConnectLoopback(int port, int receive_timeout_s);

}  // namespace snapthread::test_support
