// Which LCM provider URL a process uses.
#pragma once

#include <string>

namespace snapthread::messages {

// Loopback multicast with ttl=0: the embedded one-machine default (never leaves the host).
inline constexpr const char* kDefaultLcmUrl = "udpm://239.255.76.67:7667?ttl=0";

// The --lcm-url flag if non-empty, else the environment's LCM_DEFAULT_URL if set and
// non-empty, else kDefaultLcmUrl.
std::string ResolveLcmUrl(const std::string& flag_value);

// The kernel receive buffer a long-running receiver (viewer, logger) asks for: 2 s of the
// whole session's traffic (~2,100 messages/s of up to ~1.5 KB each, counted at the kernel's
// per-packet overhead), so a receiver the scheduler leaves off the CPU for a while under
// load catches up instead of the kernel dropping datagrams.
inline constexpr int kReceiverBufferBytes = 8 * 1024 * 1024;
// The buffer the server and the device client ask for. They receive small messages (poses,
// commands, force models), but a sender may fragment one up to LCM's limit; 1 MiB holds a
// few such messages whole while a loaded process is off the CPU, so a big bad message is
// received, counted and refused rather than silently lost in the kernel (the default
// rmem_default, 212,992 bytes, holds one 200 kB message and nothing else).
inline constexpr int kServiceBufferBytes = 1024 * 1024;

// `url` with `recv_buf_size=N` added when it is a udpm:// URL without one (other providers
// and URLs that already set it are returned unchanged). N is `bytes`, but at most
// `rmem_max` (net.core.rmem_max; LCM's udpm provider sets SO_RCVBUF, which the kernel
// silently caps there, and LCM warns on every start when it got less than it asked for).
std::string WithReceiveBuffer(const std::string& url, int bytes, long rmem_max);
// The same with this machine's /proc/sys/net/core/rmem_max (no cap when unreadable).
std::string WithReceiveBuffer(const std::string& url, int bytes = kReceiverBufferBytes);

// A one-line hint for a failed LCM start (e.g. the multicast route for udpm).
std::string LcmStartHint(const std::string& url);

}  // namespace snapthread::messages
