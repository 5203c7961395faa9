// The node's one e-stop: listeners run once per change in registration order, refusals are
// counted by source only while it is engaged.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "serial_robot_driver/core/e_stop.h"
#include "serial_robot_driver/core/motion_gate.h"

namespace {

using serial_robot_driver::core::EStop;
using serial_robot_driver::core::GateState;
using serial_robot_driver::core::MotionGate;

TEST(EStop, ListenersRunOncePerChangeInOrder) {
  EStop e_stop;
  std::vector<std::string> calls;
  e_stop.addListener([&](bool engaged) { calls.push_back(engaged ? "a on" : "a off"); });
  e_stop.addListener([&](bool engaged) { calls.push_back(engaged ? "b on" : "b off"); });
  EXPECT_FALSE(e_stop.set(false)) << "starts released";
  EXPECT_TRUE(e_stop.set(true));
  EXPECT_FALSE(e_stop.set(true)) << "a repeated message changes nothing";
  EXPECT_TRUE(e_stop.set(false));
  EXPECT_EQ(calls, (std::vector<std::string>{"a on", "b on", "a off", "b off"}));
  EXPECT_EQ(e_stop.stats().engagements, 1u);
  EXPECT_FALSE(e_stop.stats().engaged);
}

TEST(EStop, RefusesAndCountsOnlyWhileEngaged) {
  EStop e_stop;
  EXPECT_FALSE(e_stop.refuse("cmd_vel"));
  e_stop.set(true);
  EXPECT_TRUE(e_stop.engaged());
  EXPECT_TRUE(e_stop.refuse("cmd_vel"));
  EXPECT_TRUE(e_stop.refuse("cmd_vel"));
  EXPECT_TRUE(e_stop.refuse("servo/spin"));
  e_stop.set(false);
  EXPECT_FALSE(e_stop.refuse("cmd_vel"));
  const auto stats = e_stop.stats();
  EXPECT_EQ(stats.refused.at("cmd_vel"), 2u);
  EXPECT_EQ(stats.refused.at("servo/spin"), 1u);
}

// A command accepted before an e-stop never moves anything after it, even once released.
TEST(MotionGate, AnEStopVoidsWhatWasAcceptedBeforeIt) {
  MotionGate gate;
  const MotionGate::Generation before = gate.generation();
  int writes = 0;
  const auto write = [&] { return ++writes > 0; };
  bool written = false;
  EXPECT_EQ(gate.writeIfOpen(write, &written, before), GateState::kOpen);
  EXPECT_TRUE(written);
  gate.setLocked(true);
  EXPECT_EQ(gate.writeIfOpen(write, &written, before), GateState::kLocked);
  gate.setLocked(true);  // a repeated engage is the same e-stop
  gate.setLocked(false);
  EXPECT_EQ(gate.writeIfOpen(write, &written, before), GateState::kVoided)
      << "released, still void";
  EXPECT_FALSE(written);
  EXPECT_EQ(gate.generation(), before + 1);
  EXPECT_EQ(gate.writeIfOpen(write, &written, gate.generation()), GateState::kOpen);
  EXPECT_EQ(gate.writeIfOpen(write, &written), GateState::kOpen) << "no generation: gate only";
  EXPECT_EQ(writes, 3);
  EXPECT_EQ(gate.refusedAtWrite(), 2u);
  gate.close();
  EXPECT_EQ(gate.writeIfOpen(write, &written, gate.generation()), GateState::kClosed);
}

}  // namespace
