// Tests of common/realtime: the clocks, and the lock-free hand-over primitives
// (LatestValue, SpscRing) and SampleWindow's percentiles under two-thread stress.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <random>
#include <thread>
#include <vector>

#include "realtime/clock.h"
#include "realtime/latest_value.h"
#include "realtime/percentiles.h"
#include "realtime/spsc_ring.h"

namespace snapthread::realtime {
namespace {

TEST(TransportClockTest, MonotonicAdvancesAndRealtimeIsRecent) {
  const int64_t a = MonotonicMicros();
  std::this_thread::sleep_for(std::chrono::milliseconds(2));
  const int64_t b = MonotonicMicros();
  EXPECT_GE(b - a, 1500);
  EXPECT_LT(b - a, 2000000);
  EXPECT_GT(RealtimeMicros(), int64_t{1600000000} * 1000000);  // after 2020
}

// ---- LatestValue / SpscRing ------------------------------------------------------------

// A value whose fields must always agree: a torn read shows up as a mismatch.
struct Stamped {
  uint64_t seq;
  double a[16];
  uint64_t check;
};

Stamped MakeStamped(uint64_t seq) {
  Stamped s{};
  s.seq = seq;
  for (int i = 0; i < 16; ++i) s.a[i] = static_cast<double>(seq) * (i + 1);
  s.check = ~seq;
  return s;
}

bool Consistent(const Stamped& s) {
  if (s.check != ~s.seq) return false;
  for (int i = 0; i < 16; ++i) {
    if (s.a[i] != static_cast<double>(s.seq) * (i + 1)) return false;
  }
  return true;
}

TEST(TransportLatestValueTest, EmptyThenLatestWins) {
  LatestValue<Stamped> lv;
  Stamped out{};
  bool fresh = true;
  EXPECT_FALSE(lv.Read(&out, &fresh));
  EXPECT_FALSE(fresh);
  lv.Write(MakeStamped(1));
  lv.Write(MakeStamped(2));
  ASSERT_TRUE(lv.Read(&out, &fresh));
  EXPECT_TRUE(fresh);
  EXPECT_EQ(out.seq, 2u);
  ASSERT_TRUE(lv.Read(&out, &fresh));
  EXPECT_FALSE(fresh);
  EXPECT_EQ(out.seq, 2u);
  lv.Write(MakeStamped(3));
  ASSERT_TRUE(lv.Read(&out, &fresh));
  EXPECT_TRUE(fresh);
  EXPECT_EQ(out.seq, 3u);
  EXPECT_EQ(lv.writes(), 3u);
}

TEST(TransportLatestValueTest, TwoThreadStressNeverTornNeverBackwards) {
  LatestValue<Stamped> lv;
  constexpr uint64_t kWrites = 400000;
  std::atomic<bool> done{false};
  // On a loaded machine the writer can finish all its writes before the reader is first
  // scheduled, which would test nothing: every 10,000 writes it waits for a read of a
  // value written in that run of writes, so the two threads really interleave.
  std::atomic<uint64_t> seen{0};
  std::thread writer([&] {
    for (uint64_t i = 1; i <= kWrites; ++i) {
      lv.Write(MakeStamped(i));
      if (i % 10000 == 0) {
        while (seen.load(std::memory_order_acquire) + 10000 <= i) std::this_thread::yield();
      }
    }
    done.store(true);
  });
  uint64_t last = 0;
  uint64_t reads = 0, torn = 0, backwards = 0, fresh_count = 0;
  while (true) {
    const bool finished = done.load();
    bool fresh = false;
    const Stamped* s = lv.Latest(&fresh);
    if (s != nullptr) {
      seen.store(s->seq, std::memory_order_release);
      ++reads;
      if (!Consistent(*s)) ++torn;
      if (s->seq < last) ++backwards;
      if (fresh) ++fresh_count;
      last = s->seq;
    }
    if (finished) break;
  }
  writer.join();
  const Stamped* s = lv.Latest();
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->seq, kWrites);  // the final value is always delivered
  EXPECT_EQ(torn, 0u);
  EXPECT_EQ(backwards, 0u);
  EXPECT_GE(fresh_count, kWrites / 10000);  // at least one fresh value per run of writes
  EXPECT_GT(reads, 0u);
}

TEST(TransportSpscRingTest, FifoAndFull) {
  SpscRing<Stamped, 4> ring;
  Stamped out{};
  EXPECT_FALSE(ring.TryPop(&out));
  for (uint64_t i = 0; i < 4; ++i) EXPECT_TRUE(ring.TryPush(MakeStamped(i)));
  EXPECT_FALSE(ring.TryPush(MakeStamped(99)));
  EXPECT_EQ(ring.dropped(), 1u);
  EXPECT_EQ(ring.size(), 4u);
  for (uint64_t i = 0; i < 4; ++i) {
    ASSERT_TRUE(ring.TryPop(&out));
    EXPECT_EQ(out.seq, i);
  }
  EXPECT_FALSE(ring.TryPop(&out));
}

TEST(TransportSpscRingTest, TwoThreadStressDeliversEverythingInOrder) {
  auto ring = std::make_unique<SpscRing<Stamped, 64>>();  // small: forces full/empty races
  constexpr uint64_t kItems = 500000;
  std::thread producer([&] {
    for (uint64_t i = 0; i < kItems;) {
      if (ring->TryPush(MakeStamped(i))) ++i;
    }
  });
  uint64_t expected = 0, errors = 0;
  Stamped out{};
  while (expected < kItems) {
    if (ring->TryPop(&out)) {
      if (out.seq != expected || !Consistent(out)) ++errors;
      expected = out.seq + 1;
    }
  }
  producer.join();
  EXPECT_EQ(errors, 0u);
  EXPECT_EQ(expected, kItems);
  EXPECT_FALSE(ring->TryPop(&out));
}

// ---- SampleWindow ---------------------------------------------------------------------

TEST(TransportSampleWindowTest, PercentilesOfKnownSamples) {
  SampleWindow w(1000);
  EXPECT_EQ(w.Compute().count, 0u);
  // 1..1000 shuffled: p50 = 500, p99 = 990, max = 1000 (nearest rank).
  std::vector<double> v(1000);
  for (int i = 0; i < 1000; ++i) v[i] = i + 1;
  std::shuffle(v.begin(), v.end(), std::mt19937(3));
  for (double x : v) w.Push(x);
  const auto s = w.Compute();
  EXPECT_EQ(s.count, 1000u);
  EXPECT_EQ(s.p50, 500.0);
  EXPECT_EQ(s.p99, 990.0);
  EXPECT_EQ(s.max, 1000.0);
  EXPECT_DOUBLE_EQ(s.mean, 500.5);
}

TEST(TransportSampleWindowTest, KeepsOnlyTheNewestSamples) {
  SampleWindow w(10);
  for (int i = 0; i < 100; ++i) w.Push(1000.0);
  for (int i = 0; i < 10; ++i) w.Push(i);
  const auto s = w.Compute();
  EXPECT_EQ(s.count, 10u);
  EXPECT_EQ(s.max, 9.0);
  EXPECT_EQ(w.total_pushed(), 110u);
  EXPECT_THROW(SampleWindow(0), std::invalid_argument);
}

}  // namespace
}  // namespace snapthread::realtime
