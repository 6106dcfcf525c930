// Scenes: every shipped scene loads; bad scenes are refused naming file, key, expectation.
#include <fstream>
#include <utility>

#include <gtest/gtest.h>

#include "scene/scene.h"
#include "test_util.h"

namespace snapthread {
namespace {

TEST(Scenes, ShippedScenesLoad) {
  for (const char* f : {"zeeman.yaml", "cusp.yaml", "curve2d_snap.yaml", "thread3d_loop.yaml"}) {
    const Scene s = testing::SceneFile(f);
    EXPECT_FALSE(s.name.empty()) << f;
    EXPECT_GE(s.path.size(), 2u) << f;
    auto model = MakeModel(s.params);
    EXPECT_EQ(s.grasp_start.size(), model->NumControls()) << f;
  }
  const Scene t = testing::SceneFile("thread3d_loop.yaml");
  EXPECT_TRUE(t.params.Bool("grip_direction"));
  EXPECT_NEAR(t.grasp_start.tail(3).norm(), 1.0, 1e-12);
}

TEST(Scenes, OverridesApply) {
  const Scene s = testing::SceneFile("curve2d_snap.yaml", {ParseOverride("params.n=20"),
                                                          ParseOverride("solver.method=newton")});
  EXPECT_EQ(s.params.Integer("n"), 20);
  EXPECT_EQ(s.solver.method, "newton");
  EXPECT_THROW(ParseOverride("params.n"), SceneError);
  EXPECT_THROW(ParseOverride("=3"), SceneError);
}

std::string Error(const std::string& yaml) {
  try {
    ParseScene(yaml, "bad.yaml");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

const char* kGood = R"(
model: curve2d
params: {n: 10, segment_length: 1.0, bending: 1.0, stretching: 100.0}
grasp: {start: [9, 0]}
)";

TEST(Scenes, GoodTextParses) { EXPECT_EQ(Error(kGood), ""); }

TEST(Scenes, BadScenesNameFileKeyAndExpectation) {
  struct Bad {
    std::string yaml, key, expect;
  };
  const std::vector<Bad> bad = {
      {"params: {n: 3}\ngrasp: {start: [1,2]}", "model", "missing"},
      {"model: rope\ngrasp: {start: [1,2]}", "model", "expected one of"},
      {"model: curve2d\nparams: {n: 1}\ngrasp: {start: [9,0]}", "params.n", "in [2, 100000]"},
      {"model: curve2d\nparams: {n: ten}\ngrasp: {start: [9,0]}", "params.n", "an integer"},
      {"model: curve2d\nparams: {n: 10, stretching: -5}\ngrasp: {start: [9,0]}", "params.stretching", "> 0"},
      {"model: curve2d\nparams: {n: 10, bending: .nan}\ngrasp: {start: [9,0]}", "params.bending", "finite"},
      {"model: curve2d\nparams: {n: 10}\ngrasp: {start: [9,0,1]}", "grasp.start", "list of 2"},
      {"model: curve2d\nparams: {n: 10}", "grasp", "missing"},
      {"model: curve2d\nparams: {n: 10, colour: red}\ngrasp: {start: [9,0]}", "params.colour", "unknown key"},
      {"model: curve2d\nparams: {n: 10}\ngrasp: {start: [9,0]}\nsolver: {cutoff: 0}", "solver.cutoff", "> 0"},
      {"model: thread3d\nparams: {n: 5, grip_direction: true}\ngrasp: {start: [1,2,3]}", "grasp.direction", "missing"},
      {"model: zeeman\nparams: {n: 5}\ngrasp: {start: [0,3]}", "params", "no parameters"},
      {"model: curve2d\nparams: {n: 10}\ngrasp: {start: [9,0]}\ndevice: {max_force_n: -1}", "device.max_force_n", "> 0"},
      {"[1, 2", "", "not valid YAML"},
      {"model: curve2d\nmodel: cusp\nparams: {n: 10}\ngrasp: {start: [9,0]}", "model", "duplicated key"},
      {"model: curve2d\nparams: {n: 1000000000}\ngrasp: {start: [9,0]}", "params.n", "in [2, 100000]"},
      {"model: " + std::string(100000, '[') + "\n", "line 1", "nested deeper than 64"},
      {"model: curve2d\nparams: {n: 10}\ngrasp: {start: [9,0]}\n[1]: 2", "top level", "expected plain names"},
  };
  for (const Bad& b : bad) {
    const std::string e = Error(b.yaml);
    EXPECT_NE(e.find("bad.yaml"), std::string::npos) << b.yaml << " -> " << e;
    EXPECT_NE(e.find(b.key), std::string::npos) << b.yaml << " -> " << e;
    EXPECT_NE(e.find(b.expect), std::string::npos) << b.yaml << " -> " << e;
  }
}

// A FIFO, a device or a directory is refused before it is read (an open() of a FIFO
// would wait for a writer forever; /dev/zero never ends).
TEST(Scenes, NonRegularFilesAreRefusedWithoutReading) {
  for (const auto& [path, kind] : {std::pair<std::string, std::string>{"/dev/zero", "a character device"},
                                   {"/tmp", "a directory"}}) {
    try {
      LoadScene(path);
      FAIL() << path;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(path + ": is " + kind), std::string::npos) << e.what();
    }
  }
}

TEST(Scenes, MissingFileIsAClearError) {
  try {
    LoadScene("/nonexistent/scene.yaml");
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/scene.yaml"), std::string::npos);
  }
}

}  // namespace
}  // namespace snapthread
