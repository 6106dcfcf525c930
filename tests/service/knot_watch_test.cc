// server/knot_watch: the shape's knot type, off the solve thread, a few times a second.
#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "environment.h"
#include "knot_watch.h"
#include "tracking/make_tracker.h"

namespace snapthread::server {
namespace {

using Clock = KnotWatch::Clock;

// Ticks every millisecond for `seconds`, as the solve loop would.
void TickFor(KnotWatch& watch, const Scene& scene, const EquilibriumTracker& tracker,
             double seconds) {
  const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                      std::chrono::duration<double>(seconds));
  while (Clock::now() < end) {
    watch.Tick(Clock::now(), scene, tracker);
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

TEST(KnotWatchTest, ChainShapeIsIdentifiedAFewTimesASecond) {
  for (const char* file : {"thread3d_loop.yaml", "rod_greenhill.yaml", "curve2d_snap.yaml"}) {
    const Scene scene = LoadScene(test_support::ScenePath(file));
    const auto tracker = MakeTracker(scene);
    tracker->Reset(scene.grasp_start);  // as the server starts a session
    KnotWatch watch;
    EXPECT_EQ(watch.name(), "");
    TickFor(watch, scene, *tracker, 1.1);
    EXPECT_EQ(watch.name(), "unknot") << file;
    EXPECT_EQ(watch.determinant(), 1) << file;
    // kRateHz = 4: an answer at once, then one every 250 ms (a loaded machine may lose one).
    EXPECT_GE(watch.identified(), 3) << file;
    EXPECT_LE(watch.identified(), 5) << file;
    watch.Reset();
    EXPECT_EQ(watch.name(), "");
    EXPECT_EQ(watch.determinant(), 0);
  }
}

TEST(KnotWatchTest, NotComputedForModelsThatAreNotChains) {
  const Scene scene = LoadScene(test_support::ScenePath("zeeman.yaml"));
  const auto tracker = MakeTracker(scene);
  KnotWatch watch;
  TickFor(watch, scene, *tracker, 0.3);
  EXPECT_EQ(watch.name(), "");
  EXPECT_EQ(watch.determinant(), 0);
  EXPECT_EQ(watch.identified(), 0);
}

}  // namespace
}  // namespace snapthread::server
