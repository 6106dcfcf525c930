// The handler list of the patched liblcm (deploy/lcm/0002-handler-list-race.patch): a
// handler that unsubscribes handlers of the same channel while a message is being
// dispatched. Debian's liblcm 1.3.1 walks the live list by index while it shrinks: with
// handlers A, B, C and A unsubscribing B, C moves into B's place and is called again from
// the stale last slot: with two messages queued it gets the first one twice and never the
// second; the unsubscribed B is never freed (ASan's leak check), and with GLib's
// G_DEBUG=gc-friendly the stale slot is NULL and the dispatch crashes. The patched library
// calls each handler present when dispatch began at most once, skips the ones unsubscribed
// meanwhile, and frees them.
#include <unistd.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <lcm/lcm.h>

namespace {

struct Calls {
  lcm_t* lcm = nullptr;
  int a = 0, b = 0, c = 0;
  std::vector<int> c_payloads;  // first byte of each message C got
  lcm_subscription_t* sub_a = nullptr;
  lcm_subscription_t* sub_b = nullptr;
  lcm_subscription_t* sub_c = nullptr;
  bool a_unsubscribes_itself = false;
};

void OnA(const lcm_recv_buf_t*, const char*, void* user) {
  Calls& c = *static_cast<Calls*>(user);
  ++c.a;
  if (c.sub_b) {
    EXPECT_EQ(lcm_unsubscribe(c.lcm, c.sub_b), 0);
    c.sub_b = nullptr;
  }
  if (c.a_unsubscribes_itself && c.sub_a) {
    EXPECT_EQ(lcm_unsubscribe(c.lcm, c.sub_a), 0);
    c.sub_a = nullptr;
  }
}
void OnB(const lcm_recv_buf_t*, const char*, void* user) { ++static_cast<Calls*>(user)->b; }
void OnC(const lcm_recv_buf_t* rbuf, const char*, void* user) {
  Calls& c = *static_cast<Calls*>(user);
  ++c.c;
  c.c_payloads.push_back(rbuf->data_size > 0 ? static_cast<const char*>(rbuf->data)[0] : -1);
}

void PublishAndHandle(lcm_t* lcm, const char* channel) {
  const char payload[4] = {1, 2, 3, 4};
  ASSERT_EQ(lcm_publish(lcm, channel, payload, sizeof(payload)), 0);
  ASSERT_EQ(lcm_handle_timeout(lcm, 1000), 1);
}

TEST(LcmHandlerListTest, UnsubscribingAnotherHandlerDuringDispatchSkipsItAndCallsTheRestOnce) {
  // udpm (its own group on loopback): its read thread counts a message into each handler's
  // queue on arrival, as memq:// does only at dispatch, so two messages are queued here.
  Calls calls;
  calls.lcm = lcm_create("udpm://239.255.76.94:7694?ttl=0");
  ASSERT_NE(calls.lcm, nullptr) << "no multicast route? deploy/multicast-route.sh";
  const std::string channel = "HANDLERS_" + std::to_string(getpid());
  calls.sub_a = lcm_subscribe(calls.lcm, channel.c_str(), OnA, &calls);
  calls.sub_b = lcm_subscribe(calls.lcm, channel.c_str(), OnB, &calls);
  calls.sub_c = lcm_subscribe(calls.lcm, channel.c_str(), OnC, &calls);
  // Two messages queued before the first dispatch, in which A unsubscribes B.
  const char first[1] = {1}, second[1] = {2};
  ASSERT_EQ(lcm_publish(calls.lcm, channel.c_str(), first, 1), 0);
  ASSERT_EQ(lcm_publish(calls.lcm, channel.c_str(), second, 1), 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // both received
  ASSERT_EQ(lcm_handle_timeout(calls.lcm, 1000), 1);
  EXPECT_EQ(calls.a, 1);
  EXPECT_EQ(calls.b, 0) << "B was unsubscribed before its turn";
  EXPECT_EQ(calls.c_payloads, std::vector<int>({1})) << "C must get the first message once";
  ASSERT_EQ(lcm_handle_timeout(calls.lcm, 1000), 1);
  EXPECT_EQ(calls.a, 2);
  EXPECT_EQ(calls.b, 0);
  EXPECT_EQ(calls.c_payloads, std::vector<int>({1, 2})) << "C must get each message once, in order";
  lcm_destroy(calls.lcm);
}

TEST(LcmHandlerListTest, AHandlerUnsubscribingItselfAndAnotherIsFreedAndNotCalledAgain) {
  Calls calls;
  calls.a_unsubscribes_itself = true;
  calls.lcm = lcm_create("memq://");
  ASSERT_NE(calls.lcm, nullptr);
  calls.sub_a = lcm_subscribe(calls.lcm, "CH", OnA, &calls);
  calls.sub_b = lcm_subscribe(calls.lcm, "CH", OnB, &calls);
  calls.sub_c = lcm_subscribe(calls.lcm, "CH", OnC, &calls);
  PublishAndHandle(calls.lcm, "CH");
  EXPECT_EQ(calls.a, 1);
  EXPECT_EQ(calls.b, 0);
  EXPECT_EQ(calls.c, 1);
  PublishAndHandle(calls.lcm, "CH");
  EXPECT_EQ(calls.a, 1) << "A unsubscribed itself";
  EXPECT_EQ(calls.c, 2);
  lcm_destroy(calls.lcm);
}

// Another thread unsubscribes while this one dispatches: every message reaches C exactly
// once whatever the interleaving.
TEST(LcmHandlerListTest, UnsubscribeFromAnotherThreadDuringDispatch) {
  for (int round = 0; round < 200; ++round) {
    Calls calls;
    calls.lcm = lcm_create("memq://");
    ASSERT_NE(calls.lcm, nullptr);
    calls.sub_b = lcm_subscribe(calls.lcm, "CH", OnB, &calls);
    calls.sub_c = lcm_subscribe(calls.lcm, "CH", OnC, &calls);
    const char payload[1] = {0};
    for (int i = 0; i < 4; ++i) ASSERT_EQ(lcm_publish(calls.lcm, "CH", payload, 1), 0);
    std::thread other([&] { EXPECT_EQ(lcm_unsubscribe(calls.lcm, calls.sub_b), 0); });
    for (int i = 0; i < 4; ++i) ASSERT_EQ(lcm_handle_timeout(calls.lcm, 1000), 1);
    other.join();
    EXPECT_EQ(calls.c, 4) << "round " << round;
    EXPECT_LE(calls.b, 4);
    lcm_destroy(calls.lcm);
  }
}

}  // namespace
