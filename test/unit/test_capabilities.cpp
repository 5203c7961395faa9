// Cross-device wiring by kind (device/capabilities.h): what one device offers another finds by its
// kind alone, and a heading feed reaches every listener.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "serial_robot_driver/core/capabilities.h"

namespace serial_robot_driver::core {
namespace {

class StillQuery : public MotionQuery {
 public:
  explicit StillQuery(std::string why) : why_(std::move(why)) {}
  std::string motionInForce() const override { return why_; }

 private:
  std::string why_;
};

TEST(Capabilities, AKindNobodyOfferedIsNotFound) {
  Capabilities capabilities;
  EXPECT_EQ(capabilities.find<HeadingSource>(), nullptr);
  EXPECT_EQ(capabilities.find<MotionQuery>(), nullptr);
}

TEST(Capabilities, AnOfferIsFoundByItsKindOnly) {
  Capabilities capabilities;
  HeadingFeed heading;
  capabilities.offer<HeadingSource>(heading);
  EXPECT_EQ(capabilities.find<HeadingSource>(), &heading);
  EXPECT_EQ(capabilities.find<MotionQuery>(), nullptr);
}

TEST(Capabilities, TheFirstOfferOfAKindIsTheOneFound) {
  Capabilities capabilities;
  StillQuery first("base: cmd_vel in force");
  StillQuery second("other");
  capabilities.offer<MotionQuery>(first);
  capabilities.offer<MotionQuery>(second);
  ASSERT_NE(capabilities.find<MotionQuery>(), nullptr);
  EXPECT_EQ(capabilities.find<MotionQuery>()->motionInForce(), "base: cmd_vel in force");
}

TEST(HeadingFeed, EveryListenerGetsEachHeadingWithItsArrival) {
  HeadingFeed feed;
  EXPECT_FALSE(feed.wanted());
  std::vector<double> first, second;
  const Clock::time_point arrival = Clock::time_point(std::chrono::seconds(5));
  Clock::time_point seen;
  feed.addHeadingListener([&](double yaw, Clock::time_point at) {
    first.push_back(yaw);
    seen = at;
  });
  feed.addHeadingListener([&](double yaw, Clock::time_point) { second.push_back(yaw); });
  EXPECT_TRUE(feed.wanted());
  feed.publish(0.5, arrival);
  feed.publish(-1.25, arrival);
  EXPECT_EQ(first, (std::vector<double>{0.5, -1.25}));
  EXPECT_EQ(second, (std::vector<double>{0.5, -1.25}));
  EXPECT_EQ(seen, arrival);
}

}  // namespace
}  // namespace serial_robot_driver::core
