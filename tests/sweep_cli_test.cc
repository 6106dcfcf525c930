// snapthread-sweep as a user runs it: CSV contract, --back, bad arguments.
#include <sstream>

#include <gtest/gtest.h>

#include "test_support.h"
#include "test_util.h"

namespace snapthread {
namespace {

struct CliRun {
  int code;
  std::string out;
};

// Runs snapthread-sweep through the shell (stdout and stderr together), with a deadline.
CliRun Sweep(const std::string& args) {
  const test_support::ScopedTempDir dir("sweep_cli");
  test_support::ChildProcess sweep({"/bin/sh", "-c", testing::BinDir() + "/snapthread-sweep " + args},
                                   test_support::OneLog(dir.path() + "/out.txt"));
  int code = -1;
  sweep.WaitOrKill(120.0, &code);
  return {code, sweep.Out()};
}

std::string Scene(const std::string& f) { return testing::SourceDir() + "/scenes/" + f; }

TEST(SweepCli, WritesTheDocumentedCsv) {
  const CliRun r = Sweep("--scene " + Scene("cusp.yaml") + " --from -1,-1 --to 1,-1 --steps 40 --back");
  ASSERT_EQ(r.code, 0) << r.out;
  std::istringstream in(r.out);
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("step,u_x,u_y,u_z,f_x,f_y,f_z,probe,energy,residual,iterations,method,lambda_min,snapped,solve_us", 0), 0u)
      << header;
  int rows = 0, snaps = 0;
  for (std::string line; std::getline(in, line);) {
    ++rows;
    std::vector<std::string> cols;
    std::stringstream ls(line);
    for (std::string c; std::getline(ls, c, ',');) cols.push_back(c);
    ASSERT_GE(cols.size(), 15u);
    EXPECT_EQ(std::stoi(cols[0]), rows - 1);
    EXPECT_EQ(cols[11], "higher-order");
    snaps += std::stoi(cols[13]);
  }
  EXPECT_EQ(rows, 81);  // 2N+1
  EXPECT_EQ(snaps, 2);  // one jump each way across the hysteresis loop
}

TEST(SweepCli, BadArgumentsExitTwoWithAMessage) {
  CliRun r = Sweep("--scene " + Scene("cusp.yaml") + " --from -1 --to 1,-1");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("--from"), std::string::npos) << r.out;
  r = Sweep("--scene " + Scene("cusp.yaml") + " --from -1,-1 --to 1,-1 --method magic");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("--method"), std::string::npos) << r.out;
  r = Sweep("--scene /nonexistent.yaml --from -1,-1 --to 1,-1");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("/nonexistent.yaml"), std::string::npos) << r.out;
  r = Sweep("--scene " + Scene("cusp.yaml") + " --from -1,-1 --to 1,-1 --set params.n");
  EXPECT_EQ(r.code, 2);
  r = Sweep("--scene " + Scene("cusp.yaml") + " --from -1,nan --to 1,-1");
  EXPECT_EQ(r.code, 2);
  r = Sweep("--scene " + Scene("cusp.yaml") + " --from -1,-1 --to 1,-1 --steps 0");
  EXPECT_EQ(r.code, 2);
  r = Sweep("--bogus");
  EXPECT_EQ(r.code, 2);
}

}  // namespace
}  // namespace snapthread
