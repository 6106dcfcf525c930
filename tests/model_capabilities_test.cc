// The optional capabilities of each built-in model (models/model.h): each model offers
// the ones its energy has and no other, self-contact only where the params enable it, and
// what it offers works (a roll of a whole turn is no motion, the rod's frames are unit
// directors, its history moves and resets).
#include <cmath>
#include <numbers>
#include <string>
#include <utility>

#include <gtest/gtest.h>

#include "models/models.h"

namespace snapthread {
namespace {

struct Offered {
  bool band = false, contact = false, symmetry = false, history = false, frames = false, torque = false;
};

Offered OfferedBy(Model* m) {
  return Offered{.band = m->band_assembly() != nullptr,
                 .contact = m->contact() != nullptr,
                 .symmetry = m->symmetry() != nullptr,
                 .history = m->history() != nullptr,
                 .frames = m->frames() != nullptr,
                 .torque = m->grasp_torque() != nullptr};
}

std::unique_ptr<Model> Make(const std::string& name, bool contact = false) {
  ModelParams p;
  p.model = name;
  if (contact) p.Set("contact", true);
  return MakeModel(p);
}

// "band contact symmetry" for what is offered: a failure names both lists.
std::string Describe(const Offered& o) {
  std::string s;
  for (const auto& [on, name] : {std::pair{o.band, "band"}, {o.contact, "contact"}, {o.symmetry, "symmetry"},
                                 {o.history, "history"}, {o.frames, "frames"}, {o.torque, "torque"}}) {
    if (on) s += s.empty() ? name : std::string(" ") + name;
  }
  return s;
}

void ExpectOffered(const std::string& name, bool contact, const Offered& want) {
  auto m = Make(name, contact);
  EXPECT_EQ(Describe(OfferedBy(m.get())), Describe(want)) << name << (contact ? " with contact" : "");
}

TEST(ModelCapabilities, EachModelOffersWhatItsEnergyHas) {
  ExpectOffered("zeeman", false, {});
  ExpectOffered("cusp", false, {});
  ExpectOffered("curve2d", false, {.band = true});
  ExpectOffered("thread3d", false, {.band = true, .symmetry = true});
  ExpectOffered("thread3d", true, {.band = true, .contact = true, .symmetry = true});
  ExpectOffered("rod", false, {.band = true, .history = true, .frames = true, .torque = true});
  ExpectOffered("rod", true, {.band = true, .contact = true, .history = true, .frames = true, .torque = true});
}

TEST(ModelCapabilities, ThreadRollOfAWholeTurnIsNoMotion) {
  auto m = Make("thread3d");
  const SymmetryCapability* roll = m->symmetry();
  ASSERT_NE(roll, nullptr);
  Vec u(3);
  u << 0.8 * ChainSegments(ModelParams{.model = "thread3d"}), 0.3, 0.1;
  const Vec x = m->InitialState(u);
  Vec y, half;
  roll->ApplySymmetry(0, 2.0 * std::numbers::pi, x, u, &y);
  EXPECT_LT((y - x).lpNorm<Eigen::Infinity>(), 1e-12);
  roll->ApplySymmetry(0, std::numbers::pi, x, u, &half);
  EXPECT_GT((half - x).lpNorm<Eigen::Infinity>(), 1e-6) << "half a turn moves the bump";
}

TEST(ModelCapabilities, ContactBoundsAWholeStepInFreeSpace) {
  for (const std::string name : {"thread3d", "rod"}) {
    SCOPED_TRACE(name);
    auto m = Make(name, true);
    const ContactCapability* contact = m->contact();
    ASSERT_NE(contact, nullptr);
    Vec u = Vec::Zero(m->NumControls());
    u[0] = 0.9 * (name == "rod" ? 1.0 : ChainSegments(ModelParams{.model = name}));
    const Vec x = m->InitialState(u);
    // Nearly straight: no pair is active and a small step passes nothing.
    EXPECT_TRUE(contact->ActiveContacts(x, u).empty());
    const Vec dx = Vec::Constant(x.size(), 1e-4);
    EXPECT_EQ(contact->MaxStepFraction(x, dx, u), 1.0);
    EXPECT_EQ(contact->MaxMotionFraction(x, u, x + dx, u), 1.0);
  }
}

TEST(ModelCapabilities, RodFramesAreUnitDirectorsAndHistoryResets) {
  auto m = Make("rod");
  const FramesCapability* frames = m->frames();
  HistoryCapability* history = m->history();
  ASSERT_NE(frames, nullptr);
  ASSERT_NE(history, nullptr);
  Vec u = Vec::Zero(m->NumControls());
  u[0] = 0.9;
  const Vec x = m->InitialState(u);
  Eigen::Matrix3Xd nodes, d1;
  Vec twist;
  m->NodePositions(x, u, &nodes);
  frames->MaterialFrames(x, u, &d1, &twist);
  ASSERT_EQ(d1.cols(), nodes.cols() - 1);
  ASSERT_EQ(twist.size(), d1.cols());
  for (Eigen::Index j = 0; j < d1.cols(); ++j) {
    EXPECT_NEAR(d1.col(j).norm(), 1.0, 1e-12) << "edge " << j;
    EXPECT_NEAR(d1.col(j).dot((nodes.col(j + 1) - nodes.col(j)).normalized()), 0.0, 1e-12) << "edge " << j;
  }
  // The grasp rolled by whole steps of less than half a turn: each accepted state keeps
  // its energy, and the history counts the turn (past half a turn a fresh model reads
  // the roll the other way round), until a reset gives a fresh model's energy again.
  const auto fresh = Make("rod");
  auto rolled = [&](double roll) {
    Vec v = u;
    v[3] = roll;
    return v;
  };
  for (double roll : {1.0, 2.0, 3.0}) {
    const Vec ur = rolled(roll), xr = m->InitialState(ur);
    const double e = m->Energy(xr, ur);
    history->AcceptState(xr, ur);
    EXPECT_NEAR(m->Energy(xr, ur), e, 1e-12 * (1.0 + std::abs(e))) << "roll " << roll;
  }
  const Vec ur = rolled(3.5), xr = m->InitialState(ur);
  EXPECT_GT(std::abs(m->Energy(xr, ur) - fresh->Energy(xr, ur)), 1e-3);
  history->ResetHistory();
  EXPECT_EQ(m->Energy(xr, ur), fresh->Energy(xr, ur));
}

}  // namespace
}  // namespace snapthread
